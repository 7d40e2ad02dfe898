// The animation of report.html, one per scenario: every simulator's ball
// moving in its room at once, as the seed document's program draws it (first
// frame, then for each step the next state, cleared and redrawn). page.js
// creates one with BouncecheckAnimation.create; nothing here reads the page's
// data on its own.
//
// Frames are built from the decimated paths the page already carries (every
// velocity reversal kept: reports/plot_data.h), interpolated linearly between
// kept samples, so the page does not grow with the run's length. Drawing is
// a 2D canvas: circles of the true radius in the 2D square; in 3D an
// orthographic view of the wire-frame room, rotated by dragging (a sphere
// projects to a disc of its true radius, with its shadow on the floor).
//
// The browser test (web/test/browser-check.mjs) drives each animation
// through window.bouncecheckAnimations[scenario index]: seek, visibility,
// project (scene metres to canvas pixels) and position (a ball's centre).
"use strict";

window.BouncecheckAnimation = (function () {
  const SPEEDS = [1, 2, 5, 10, 20, 50];  // 1: real time, as the document's loop paces itself
  const WALLS = ["x lower", "x upper", "y lower", "y upper", "z lower", "z upper"];

  // The index of the last kept sample at or before t (0 before the first).
  function sampleBefore(times, t) {
    let lo = 0, hi = times.length - 1;
    if (hi < 0 || t <= times[0]) return 0;
    if (t >= times[hi]) return hi;
    while (hi - lo > 1) {
      const mid = (lo + hi) >> 1;
      if (times[mid] <= t) lo = mid; else hi = mid;
    }
    return lo;
  }

  // The centre at t, linear between kept samples; the last kept sample after
  // the run's end. Coordinates a 2D path lacks are 0.
  function positionAt(path, t) {
    const times = path.t, n = times.length;
    if (n === 0) return null;
    const i = sampleBefore(times, t), j = Math.min(i + 1, n - 1);
    const span = times[j] - times[i];
    const f = span > 0 ? Math.min(Math.max((t - times[i]) / span, 0), 1) : 0;
    const at = (axis) => {
      const c = path[axis];
      if (!c || c[i] === null || c[j] === null) return c && c[i] !== null ? c[i] : 0;
      return c[i] + f * (c[j] - c[i]);
    };
    return [at("x"), at("y"), at("z")];
  }

  function el(tag, attrs, children) {
    const node = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) node.setAttribute(k, v);
    for (const child of [].concat(children === undefined ? [] : children))
      node.appendChild(typeof child === "string" ? document.createTextNode(child) : child);
    return node;
  }

  // options: { scenario, balls: [{name, colour, path, contacts: {t, wall}}],
  //            absent: [{name, reason}] }
  function create(container, options) {
    const s = options.scenario, dim = s.dim, room = s.room;
    const balls = options.balls.map((b) => Object.assign({ visible: true }, b));
    const duration = Math.max(s.duration, ...balls.map((b) => (b.path.t.length ? b.path.t[b.path.t.length - 1] : 0)));
    const trail = Math.min(3, duration / 8);  // seconds of path behind each ball
    let t = 0, speed = 1, playing = false, lastFrame = null;
    let yaw = -0.6, pitch = 0.35;  // 3D view: about the vertical, then tilted towards the viewer

    // ---------------------------------------------------------- controls
    const play = el("button", { type: "button", class: "play" }, "▶ play");
    const speedSelect = el("select", { "aria-label": "speed" },
      SPEEDS.map((v) => el("option", { value: String(v) }, v === 1 ? "real time" : v + "×")));
    const slider = el("input", { type: "range", min: "0", max: String(duration), step: String(duration / 2000),
                                 value: "0", "aria-label": "time" });
    const clock = el("span", { class: "clock" }, "");
    const legend = el("div", { class: "legend" });
    const canvas = el("canvas", { class: "animation-canvas" });
    const side = el("div", { class: "animation-side" }, [legend]);
    if (options.absent.length) {
      side.appendChild(el("p", { class: "note" }, "Not shown:"));
      side.appendChild(el("ul", { class: "absent" },
        options.absent.map((a) => el("li", {}, a.name + ": " + a.reason))));
    }
    if (dim === 3) side.appendChild(el("p", { class: "note" }, "Drag the room to rotate it, playing or not."));
    container.appendChild(el("div", { class: "animation-controls" }, [play, speedSelect, slider, clock]));
    container.appendChild(el("div", { class: "animation-body" }, [canvas, side]));

    for (const b of balls) {
      const entry = el("button", { type: "button", class: "legend-entry", "data-name": b.name },
        [el("span", { class: "swatch", style: "background:" + b.colour }), b.name]);
      entry.addEventListener("click", () => setVisible(b.name, !b.visible));
      b.entry = entry;
      legend.appendChild(entry);
    }

    // ---------------------------------------------------------- projection
    let width = 0, height = 0, scale = 1, origin = [0, 0];
    const centre = [room[0] / 2, room[1] / 2, dim === 3 ? room[2] / 2 : 0];

    // Scene metres to the camera frame: x right, y up, depth towards the viewer.
    function view(p) {
      if (dim === 2) return [p[0] - centre[0], p[1] - centre[1], 0];
      const x = p[0] - centre[0], y = p[1] - centre[1], z = p[2] - centre[2];
      const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
      const x1 = cy * x - sy * y, y1 = sy * x + cy * y;  // about z
      return [x1, cp * z - sp * y1, sp * z + cp * y1];   // tilted about the screen's x
    }
    // Scene metres to canvas CSS pixels.
    function project(p) {
      const v = view(p);
      return { x: origin[0] + scale * v[0], y: origin[1] - scale * v[1], depth: v[2] };
    }

    function resize() {
      const w = Math.max(240, Math.floor(canvas.clientWidth || container.clientWidth * 0.72));
      const h = Math.min(Math.max(320, Math.round(w * 0.62)), 720);
      if (w === width && h === height) return;
      width = w;
      height = h;
      const ratio = window.devicePixelRatio || 1;
      canvas.width = Math.round(w * ratio);
      canvas.height = Math.round(h * ratio);
      canvas.style.height = h + "px";
      canvas.getContext("2d").setTransform(ratio, 0, 0, ratio, 0, 0);
      const margin = 16;
      // The whole room fits at every rotation: in 3D its bounding sphere.
      const extent = dim === 2 ? [room[0], room[1]] : [1, 1].map(() => Math.hypot(room[0], room[1], room[2]));
      scale = Math.min((w - 2 * margin) / extent[0], (h - 2 * margin) / extent[1]);
      origin = [w / 2, h / 2];
    }

    // ---------------------------------------------------------- drawing
    function corners() {
      const [a, b, c] = [room[0], room[1], dim === 3 ? room[2] : 0];
      return [[0, 0, 0], [a, 0, 0], [a, b, 0], [0, b, 0], [0, 0, c], [a, 0, c], [a, b, c], [0, b, c]];
    }
    // Each wall's outline, as corner indices (2D: the wall's edge only).
    const FACES_3D = { "x lower": [0, 3, 7, 4], "x upper": [1, 2, 6, 5], "y lower": [0, 1, 5, 4],
                       "y upper": [3, 2, 6, 7], "z lower": [0, 1, 2, 3], "z upper": [4, 5, 6, 7] };
    const EDGES_2D = { "x lower": [0, 3], "x upper": [1, 2], "y lower": [0, 1], "y upper": [3, 2] };

    // How strongly each wall flashes: contacts in the last 0.25 s of
    // playback (scaled by the speed), fading with age.
    function flashes() {
      const window_ = 0.25 * speed, out = {};
      for (const b of balls) {
        if (!b.visible) continue;
        const ts = b.contacts.t;
        for (let k = sampleBefore(ts, t); k >= 0 && k < ts.length; --k) {
          if (ts[k] > t) continue;
          const age = t - ts[k];
          if (age > window_) break;
          out[b.contacts.wall[k]] = Math.max(out[b.contacts.wall[k]] || 0, 1 - age / window_);
        }
      }
      return out;
    }

    function draw() {
      resize();
      const g = canvas.getContext("2d");
      g.clearRect(0, 0, width, height);
      g.fillStyle = "#ffffff";
      g.fillRect(0, 0, width, height);
      const c = corners().map(project);
      const flash = flashes();
      // Walls: a flash fills the face (3D) or thickens the edge (2D).
      g.lineJoin = "round";
      for (const wall of WALLS) {
        const strength = flash[wall];
        if (!strength) continue;
        if (dim === 3) {
          const f = FACES_3D[wall].map((k) => c[k]);
          g.beginPath();
          g.moveTo(f[0].x, f[0].y);
          for (const q of f.slice(1)) g.lineTo(q.x, q.y);
          g.closePath();
          g.fillStyle = "rgba(255, 196, 0, " + (0.35 * strength).toFixed(3) + ")";
          g.fill();
        } else if (EDGES_2D[wall]) {
          const [i, j] = EDGES_2D[wall];
          g.strokeStyle = "rgba(255, 170, 0, " + strength.toFixed(3) + ")";
          g.lineWidth = 6;
          g.beginPath();
          g.moveTo(c[i].x, c[i].y);
          g.lineTo(c[j].x, c[j].y);
          g.stroke();
        }
      }
      g.strokeStyle = "#999999";
      g.lineWidth = 1;
      g.beginPath();
      const edges = dim === 3
        ? [[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 7], [7, 4], [0, 4], [1, 5], [2, 6], [3, 7]]
        : [[0, 1], [1, 2], [2, 3], [3, 0]];
      for (const [i, j] of edges) { g.moveTo(c[i].x, c[i].y); g.lineTo(c[j].x, c[j].y); }
      g.stroke();

      const shown = [];
      for (const b of balls) {
        if (!b.visible) continue;
        const p = positionAt(b.path, t);
        if (p) shown.push({ ball: b, p: p, q: project(p) });
      }
      // Trails: 40 points over the last `trail` seconds, fading with age.
      g.lineWidth = 1.5;
      for (const { ball } of shown) {
        let previous = null;
        for (let k = 0; k <= 40; ++k) {
          const tk = Math.max(0, t - trail + (trail * k) / 40);
          const q = project(positionAt(ball.path, tk));
          if (previous) {
            g.strokeStyle = ball.colour;
            g.globalAlpha = 0.5 * (k / 40);
            g.beginPath();
            g.moveTo(previous.x, previous.y);
            g.lineTo(q.x, q.y);
            g.stroke();
          }
          previous = q;
        }
      }
      g.globalAlpha = 1;
      const radius = Math.max(2, s.radius * scale);
      if (dim === 3) {  // shadows on the floor, under every ball
        g.fillStyle = "rgba(0, 0, 0, 0.12)";
        for (const { p } of shown) {
          const f = project([p[0], p[1], 0]);
          g.beginPath();
          g.ellipse(f.x, f.y, radius, radius * Math.max(0.2, Math.abs(Math.sin(pitch))), 0, 0, 2 * Math.PI);
          g.fill();
        }
      }
      shown.sort((a, b) => a.q.depth - b.q.depth);  // farthest first
      for (const { ball, q } of shown) {
        g.beginPath();
        g.arc(q.x, q.y, radius, 0, 2 * Math.PI);
        g.fillStyle = ball.colour;
        g.fill();
        g.strokeStyle = "rgba(0, 0, 0, 0.55)";
        g.lineWidth = 1;
        g.stroke();
      }
      clock.textContent = "t = " + t.toFixed(2) + " s of " + duration.toFixed(2) + " s";
      if (Number(slider.value) !== t) slider.value = String(t);
    }

    // ---------------------------------------------------------- playback
    function frame(now) {
      if (!playing) return;
      if (lastFrame !== null) t = Math.min(duration, t + ((now - lastFrame) / 1000) * speed);
      lastFrame = now;
      draw();
      if (t >= duration) setPlaying(false);
      else requestAnimationFrame(frame);
    }
    function setPlaying(on) {
      if (on && t >= duration) t = 0;
      playing = on;
      lastFrame = null;
      play.textContent = on ? "❚❚ pause" : "▶ play";
      if (on) requestAnimationFrame(frame);
    }
    function seek(time) {
      t = Math.min(Math.max(Number(time) || 0, 0), duration);
      draw();
    }
    function setVisible(name, on) {
      for (const b of balls) {
        if (b.name !== name) continue;
        b.visible = on;
        b.entry.classList.toggle("off", !on);
      }
      draw();
    }
    play.addEventListener("click", () => setPlaying(!playing));
    speedSelect.addEventListener("change", () => { speed = Number(speedSelect.value); });
    slider.addEventListener("input", () => seek(slider.value));
    if (dim === 3) {
      let drag = null;
      canvas.addEventListener("pointerdown", (e) => { drag = [e.clientX, e.clientY]; canvas.setPointerCapture(e.pointerId); });
      canvas.addEventListener("pointermove", (e) => {
        if (!drag) return;
        yaw -= (e.clientX - drag[0]) * 0.01;
        pitch = Math.min(Math.PI / 2, Math.max(-Math.PI / 2, pitch + (e.clientY - drag[1]) * 0.01));
        drag = [e.clientX, e.clientY];
        if (!playing) draw();
      });
      canvas.addEventListener("pointerup", () => { drag = null; });
    }
    window.addEventListener("resize", () => { if (!playing) draw(); });
    draw();

    return {
      seek: seek,
      setVisible: setVisible,
      play: () => setPlaying(true),
      pause: () => setPlaying(false),
      time: () => t,
      duration: duration,
      canvas: canvas,
      radiusPixels: () => Math.max(2, s.radius * scale),
      project: (p) => { const q = project(p); return { x: q.x, y: q.y }; },
      position: (name) => { const b = balls.find((x) => x.name === name); return b ? positionAt(b.path, t) : null; },
      names: () => balls.map((b) => b.name),
    };
  }

  return { create: create, positionAt: positionAt };
})();
