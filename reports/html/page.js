// The script of report.html and sweep.html. It builds every table and plot
// from the JSON in #bouncecheck-data (written by reports/html_report.cpp or
// reports/sweep_report.cpp) with the inlined Plotly. It asks no server for anything.
//
// Each plot is a div with class "plot" and data-plot-kind; the browser test
// (web/test/browser-check.mjs) checks each one's trace count against
// report.json, so the trace layout below is a contract:
//   path        one line per simulator that ran, plus the room
//   height      per simulator that ran, its line and its contact markers
//   apex        per simulator that ran except exact, its bars; plus exact's markers
//   divergence  per simulator that ran except reference
//   error       per simulator that ran except exact
//   normal      per simulator that ran, plus the alpha line
//   tangential  per simulator that ran, plus the beta line
//   (sweep.html) work-precision: per simulator, plus the Pareto front
"use strict";

(function () {
  const data = JSON.parse(document.getElementById("bouncecheck-data").textContent);
  const page = document.getElementById("page");

  const NAMED_COLOURS = { reference: "#222222", exact: "#8c8c8c", bullet: "#1f77b4", ode: "#ff7f0e", box2d: "#2ca02c" };
  const PALETTE = ["#d62728", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22"];
  const assigned = {};
  function colour(name) {
    const base = name.split(" ")[0];
    if (NAMED_COLOURS[base]) return NAMED_COLOURS[base];
    if (!(base in assigned)) assigned[base] = PALETTE[Object.keys(assigned).length % PALETTE.length];
    return assigned[base];
  }

  // ------------------------------------------------------------ DOM helpers

  function el(tag, attrs, children) {
    const node = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs || {})) node.setAttribute(k, v);
    for (const child of [].concat(children === undefined ? [] : children)) {
      node.appendChild(typeof child === "string" || typeof child === "number" ? document.createTextNode(String(child)) : child);
    }
    return node;
  }

  // cells: strings, or {text, cls, href, sort} for a coloured verdict, a
  // link, or a sort key other than the text. A click on a header sorts the
  // rows by that column (numbers by value, "-" last), again to reverse.
  function table(headers, rows, cls) {
    const cell = (c) => {
      if (c === null || typeof c !== "object") return el("td", {}, c === null ? "-" : String(c));
      const td = el("td", { class: c.cls || "" }, c.href ? el("a", { href: c.href }, c.text) : c.text);
      if (c.sort !== undefined) td.dataset.sort = String(c.sort);
      return td;
    };
    const body = el("tbody", {}, rows.map((cells) => el("tr", {}, cells.map(cell))));
    const head = el("thead", {}, el("tr", {}, headers.map((h, column) => {
      const th = el("th", { class: "sortable", title: "sort" }, h);
      th.addEventListener("click", () => sortRows(body, column, th));
      return th;
    })));
    return el("table", { class: cls || "" }, [head, body]);
  }

  function sortKey(td) {
    const text = td.dataset.sort !== undefined ? td.dataset.sort : td.textContent;
    const value = parseFloat(text);
    return { text: text, value: /^[-+]?[0-9.]/.test(text) && Number.isFinite(value) ? value : null };
  }

  function sortRows(body, column, th) {
    const descending = th.dataset.order === "ascending";
    for (const other of th.parentNode.children) delete other.dataset.order;
    th.dataset.order = descending ? "descending" : "ascending";
    const rows = Array.from(body.rows);
    rows.sort((a, b) => {
      const x = sortKey(a.cells[column] || b.cells[column]), y = sortKey(b.cells[column] || a.cells[column]);
      if (x.value === null || y.value === null) {
        if (x.value !== y.value) return x.value === null ? 1 : -1;  // "-" and words last
        return (descending ? -1 : 1) * x.text.localeCompare(y.text);
      }
      return (descending ? -1 : 1) * (x.value - y.value);
    });
    for (const row of rows) body.appendChild(row);
  }

  function num(v, digits) {
    if (v === null || v === undefined || Number.isNaN(v)) return "-";
    return Number(v).toPrecision(digits || 4);
  }
  function percent(v) { return v === null || v === undefined ? "-" : (100 * v).toFixed(2) + " %"; }
  function vec(v) { return "(" + v.map((x) => num(x, 4)).join(", ") + ")"; }
  function positive(values) { return values.map((v) => (v !== null && v > 0 ? v : null)); }

  // ------------------------------------------------------------ plots

  const CONFIG = { displaylogo: false, responsive: true };

  function addPlot(grid, id, kind, title, traces, layout, wide) {
    const div = el("div", { id: id, class: "plot" + (wide ? " wide" : ""), "data-plot-kind": kind });
    grid.appendChild(div);
    const base = {
      title: { text: title, font: { size: 14 } },
      margin: { l: 60, r: 20, t: 40, b: 45 },
      legend: { orientation: "h", y: -0.2 },
      hovermode: "closest",
    };
    Plotly.newPlot(div, traces, Object.assign(base, layout || {}), CONFIG);
  }

  function axisTitle(text, extra) { return Object.assign({ title: { text: text } }, extra || {}); }

  const AXES = ["x", "y", "z"];

  function roomTrace2d(room) {
    return { x: [0, room[0], room[0], 0, 0], y: [0, 0, room[1], room[1], 0], mode: "lines", name: "room",
             line: { color: "#999", width: 1 }, hoverinfo: "skip" };
  }

  function roomTrace3d(room) {
    const [a, b, c] = room;
    const corners = [[0, 0, 0], [a, 0, 0], [a, b, 0], [0, b, 0], [0, 0, c], [a, 0, c], [a, b, c], [0, b, c]];
    const edges = [[0, 1], [1, 2], [2, 3], [3, 0], [4, 5], [5, 6], [6, 7], [7, 4], [0, 4], [1, 5], [2, 6], [3, 7]];
    const t = { x: [], y: [], z: [], type: "scatter3d", mode: "lines", name: "room",
                line: { color: "#999", width: 2 }, hoverinfo: "skip" };
    for (const [i, j] of edges) {
      for (const k of [i, j]) { t.x.push(corners[k][0]); t.y.push(corners[k][1]); t.z.push(corners[k][2]); }
      t.x.push(null); t.y.push(null); t.z.push(null);
    }
    return t;
  }

  function pathPlot(grid, id, scenario, ran) {
    const room = scenario.room;
    if (scenario.dim === 2) {
      const traces = ran.map((s) => ({ x: s.plot.path.x, y: s.plot.path.y, mode: "lines", name: s.name,
                                       line: { color: colour(s.name), width: 1.5 } }));
      traces.push(roomTrace2d(room));
      addPlot(grid, id, "path", "Path of the ball's centre", traces, {
        xaxis: axisTitle("x (m)", { range: [-0.02 * room[0], 1.02 * room[0]], constrain: "domain" }),
        yaxis: axisTitle("y (m)", { scaleanchor: "x", range: [-0.02 * room[1], 1.02 * room[1]] }),
        legend: { orientation: "v", x: 1.02, y: 1 },
      }, true);
      return;
    }
    const traces = ran.map((s) => ({ x: s.plot.path.x, y: s.plot.path.y, z: s.plot.path.z, type: "scatter3d",
                                     mode: "lines", name: s.name, line: { color: colour(s.name), width: 3 } }));
    traces.push(roomTrace3d(room));
    addPlot(grid, id, "path", "Path of the ball's centre (drag to rotate)", traces, {
      scene: {
        aspectmode: "data",
        xaxis: { title: { text: "x (m)" }, range: [0, room[0]] },
        yaxis: { title: { text: "y (m)" }, range: [0, room[1]] },
        zaxis: { title: { text: "z (m)" }, range: [0, room[2]] },
        // Far enough out that the floor and the axis titles stay in the frame.
        camera: { eye: { x: 1.5, y: -1.5, z: 0.95 }, center: { x: 0, y: 0, z: -0.1 } },
        domain: { x: [0, 0.85], y: [0, 1] },
      },
      legend: { orientation: "v", x: 0.86, y: 1 },
      margin: { l: 10, r: 10, t: 40, b: 10 },
    }, true);
  }

  // Contacts are drawn up to the simulator's rest; after it a resting ball
  // touches the floor at almost every step, so those are counted instead.
  function heightPlot(grid, id, vertical, ran) {
    const traces = [], after = [];
    for (const s of ran) {
      const rest = s.result.rest_time;
      const c = s.plot.contacts;
      const before = c.t.map((ct, i) => i).filter((i) => rest === null || rest === undefined || c.t[i] < rest);
      const later = c.t.length - before.length;
      if (later > 0) after.push(s.name + ": " + later + (c.t.length >= 500 ? "+" : "") + " after rest at t = " + num(rest, 4) + " s");
      traces.push({ x: s.plot.path.t, y: s.plot.path[AXES[vertical]], mode: "lines", name: s.name, legendgroup: s.name,
                    line: { color: colour(s.name), width: 1.5 } });
      traces.push({ x: before.map((i) => c.t[i]), y: before.map((i) => c.height[i]), text: before.map((i) => c.wall[i]),
                    mode: "markers", name: s.name + " contacts", legendgroup: s.name, showlegend: false,
                    marker: { color: colour(s.name), size: 6, symbol: "circle-open" },
                    hovertemplate: "%{text} wall at t = %{x:.4f} s<extra>" + s.name + "</extra>" });
    }
    addPlot(grid, id, "height", "Vertical coordinate against time (circles: contacts before rest)", traces, {
      xaxis: axisTitle("t (s)"), yaxis: axisTitle(AXES[vertical] + " of the centre (m)"),
    }, true);
    if (after.length) grid.appendChild(el("p", { class: "note wide-note" }, "Contacts not drawn: " + after.join("; ") + "."));
  }

  function apexPlot(grid, id, plots, ran) {
    const shown = 12;
    const traces = [];
    for (const s of ran) {
      if (s.name === "exact") continue;
      const heights = (s.result.apexes || []).slice(0, shown).map((a) => a.height);
      traces.push({ type: "bar", x: heights.map((_, i) => i + 1), y: heights, name: s.name,
                    marker: { color: colour(s.name) } });
    }
    const exact = plots.exact_apexes.height.slice(0, shown);
    traces.push({ x: exact.map((_, i) => i + 1), y: exact, mode: "markers", name: "exact",
                  marker: { color: "#000", symbol: "diamond", size: 9 } });
    const all = traces.flatMap((t) => t.y).filter((v) => v !== null);
    const low = all.length ? Math.min(...all) : 0, high = all.length ? Math.max(...all) : 1;
    addPlot(grid, id, "apex", "Apex height per bounce", traces, {
      barmode: "group",
      xaxis: axisTitle("apex", { dtick: 1 }),
      yaxis: axisTitle("centre height at the apex (m)", { range: [Math.max(0, low - 0.1 * (high - low) - 1e-3), high + 0.05 * (high - low) + 1e-3] }),
    });
  }

  // The baseline's rest is marked: after it the distance measures how the
  // ball slides or rolls on the floor, not how it bounces, and it jumps.
  function distancePlot(grid, id, kind, title, ran, skip, field, baselineRest) {
    const traces = ran.filter((s) => s.name !== skip).map((s) => ({
      x: s.plot[field].t, y: positive(s.plot[field].d), mode: "lines", name: s.name,
      line: { color: colour(s.name), width: 1.5 } }));
    const rest = baselineRest === null || baselineRest === undefined ? [] : [baselineRest];
    addPlot(grid, id, kind, title, traces, {
      xaxis: axisTitle("t (s)"), yaxis: axisTitle("centre distance (m)", { type: "log", exponentformat: "power" }),
      shapes: rest.map((x) => ({ type: "line", xref: "x", yref: "paper", x0: x, x1: x, y0: 0, y1: 1,
                                 line: { color: "#555", dash: "dot", width: 1 } })),
      annotations: rest.map((x) => ({ x: x, xref: "x", y: 1, yref: "paper", xanchor: "left", yanchor: "top",
                                      showarrow: false, font: { size: 11, color: "#555" },
                                      text: " " + skip + " at rest: after this, sliding, not bouncing" })),
    });
  }

  function dampingPlot(grid, id, kind, title, scenario, ran, field, lawName, lawValue) {
    const traces = ran.map((s) => ({ x: s.plot.damping.t, y: s.plot.damping[field], mode: "markers", name: s.name,
                                     marker: { color: colour(s.name), size: 7, opacity: 0.8 } }));
    traces.push({ x: [0, scenario.duration], y: [lawValue, lawValue], mode: "lines", name: lawName + " = " + lawValue,
                  line: { color: "#000", dash: "dash", width: 1 } });
    addPlot(grid, id, kind, title, traces, {
      xaxis: axisTitle("contact time (s)"), yaxis: axisTitle("measured " + lawName),
    });
  }

  // ------------------------------------------------------------ run report

  const EXACT = "exact", REFERENCE = "reference";
  const scenarioLink = (index) => "#scenario-" + index;

  // What the thresholds say: which failed and by how much, not a count alone.
  function verdict(result) {
    if (result.status === "skipped") return { text: "skipped", cls: "skip" };
    if (result.status === "failed") return { text: "failed", cls: "fail" };
    const c = result.comparison;
    if (!c) return { text: "ok", cls: "" };
    if (c.thresholds.length === 0) return { text: "none set", cls: "" };
    const failed = c.thresholds.filter((t) => !t.passed);
    return failed.length
      ? { text: failed.map((t) => t.metric + " " + num(t.measured, 3) + " > " + num(t.limit, 3)).join("; "), cls: "fail" }
      : { text: "all " + c.thresholds.length + " held", cls: "pass" };
  }

  // The figures that rank a simulator against exact and the reference, as
  // the terminal's table; null where there is nothing to rank (exact against itself).
  function rankingFigures(r) {
    const c = r.comparison;
    if (!c || r.status !== "ok") return null;
    const own = r.simulator === c.vs_exact.baseline;
    const e = c.vs_exact;
    return {
      apexError: own || !e.bounces.length ? null : e.bounce_height_rel_max,
      contactError: own ? null : e.contact_time_max,
      // Never leaving the band ranks above any time.
      tracks: own || !e.trajectory.samples ? null
        : e.trajectory.first_exceeds === null ? Infinity : e.trajectory.first_exceeds,
      apexDivergence: r.simulator === REFERENCE || !c.vs_reference.bounces.length ? null : c.vs_reference.bounce_height_rel_max,
    };
  }

  function tracksText(v) { return v === null ? "-" : v === Infinity ? "whole run" : num(v, 3) + " s"; }

  function overviewRow(scenarioName, index, r) {
    const c = r.comparison, f = rankingFigures(r);
    const damping = !c ? "-" : c.damping.reproduces ? { text: "ok", cls: "pass" } : { text: c.damping.verdict, cls: "warn" };
    const cell = (v, text) => (v === null || v === undefined ? "-" : { text: text, sort: v === Infinity ? 1e300 : v });
    return [
      { text: scenarioName, href: scenarioLink(index) }, r.simulator,
      r.status !== "ok" ? { text: r.status + (r.reason ? ": " + r.reason : ""), cls: r.status === "failed" ? "fail" : "skip" }
        : r.filled_from === null || r.filled_from === undefined ? "ok"
        : "ok; states repeat from t = " + num(r.filled_from, 4) + " s (the last " + r.fill_steps + " filled, not computed)",
      f ? cell(f.apexError, percent(f.apexError)) : "-",
      f ? cell(f.contactError, num(f.contactError, 3)) : "-",
      f ? cell(f.tracks, tracksText(f.tracks)) : "-",
      c && f && f.tracks !== null ? num(c.vs_exact.trajectory.rms_before_rest, 3) : "-",
      c && c.vs_reference.bounces.length ? percent(c.vs_reference.bounce_height_rel_max) : "-",
      c && c.vs_reference.trajectory.samples ? num(c.vs_reference.trajectory.rms_before_rest, 3) : "-",
      c && c.damping.contacts ? num(c.damping.normal_mean, 4) : "-",
      c && c.damping.tangential_contacts ? num(c.damping.tangential_mean, 4) : "-",
      damping, verdict(r),
    ];
  }

  // One ranked figure's leader as report.json's "ranking" has it (ties listed together).
  function leaderText(l, format) {
    return l ? l.simulators.join(", ") + " (" + format(l.value === null ? Infinity : l.value) + ")" : "-";
  }

  // The ranking per scenario, first on the page: who is closest to exact on
  // each figure that ranks (bounce heights, contact times, how long it tracks),
  // and who is closest to the reference. Engines only, ranked by bouncecheck
  // (verdicts/ranking.h) as the terminal's line.
  function rankingTable(report) {
    const rows = report.scenarios.map((entry, index) => {
      const r = entry.ranking;
      return [
        { text: entry.scenario.name, href: scenarioLink(index) },
        leaderText(r.apex_error, percent),
        leaderText(r.contact_error, (v) => num(v, 3) + " s"),
        leaderText(r.tracks_exact, tracksText),
        leaderText(r.apex_divergence, percent),
      ];
    });
    return table(["scenario", "closest to exact: apex heights", "closest to exact: contact times",
                  "tracks exact longest", "closest to the reference: apex heights"], rows, "ranking");
  }

  // The distance within which a simulator "tracks" exact, as the report's comparisons measured it.
  function trackingTolerance(results) {
    const compared = results.find((r) => r.comparison);
    return compared ? num(compared.comparison.vs_exact.trajectory.tolerance) : "-";
  }

  function renderRun() {
    const report = data.report;
    const results = report.scenarios.flatMap((s) => s.simulators);
    const failed = results.filter((r) => r.status === "failed").length;
    const exceeded = results.filter((r) => r.comparison && !r.comparison.passed).length;
    const overall = failed ? { text: failed + " simulator(s) failed", cls: "fail" }
      : exceeded ? { text: exceeded + " simulator run(s) exceeded a threshold", cls: "fail" }
      : { text: "every threshold held", cls: "pass" };

    page.appendChild(el("h1", {}, "bouncecheck report"));
    page.appendChild(el("p", { class: "lede" }, [
      el("span", { class: "badge " + overall.cls, id: "overall" }, overall.text), " ",
      report.scenarios.length + " scenario(s), bouncecheck " + report.bouncecheck_version +
      ". Divergence is measured against the reference (the document's model, bit for bit), error against exact (its continuous-time solution)."]));

    page.appendChild(el("h2", { id: "ranking" }, "Ranking"));
    page.appendChild(rankingTable(report));
    page.appendChild(el("p", { class: "note" },
      "Engines only (the reference and exact are the baselines). Apex heights: the largest relative error over the " +
      "compared bounces; contact times: the largest floor-contact time error; tracking: how long the ball stays within " +
      trackingTolerance(results) + " m of exact."));

    page.appendChild(el("h2", { id: "contents" }, "Contents"));
    page.appendChild(el("ol", { class: "contents" }, report.scenarios.map((entry, index) => {
      const bad = entry.simulators.filter((r) => r.status === "failed" || (r.comparison && !r.comparison.passed)).length;
      return el("li", {}, [el("a", { href: scenarioLink(index) }, entry.scenario.name),
        " — " + entry.simulators.filter((r) => r.status !== "skipped").length + " ran" + (bad ? ", " + bad + " failed or exceeded" : "")]);
    })));

    const rows = report.scenarios.flatMap((s, index) => s.simulators.map((r) => overviewRow(s.scenario.name, index, r)));
    const overview = el("details", { open: "" }, [el("summary", {}, "Every simulator on every scenario (" + rows.length +
      " rows; click a header to sort)"),
      table(["scenario", "simulator", "status", "Δ apex vs exact", "contact time error (s)",
             "tracks exact for", "RMS vs exact before rest (m)", "Δ apex vs reference",
             "RMS vs reference before rest (m)", "measured alpha", "measured beta", "damping",
             "thresholds"], rows, "overview")]);
    page.appendChild(overview);
    page.appendChild(el("p", { class: "note" },
      "RMS is taken before the baseline's rest: after it, sliding dominates a whole-run RMS (report.json has both). " +
      "Damping: ok when the measured coefficients follow the law, else what differs and by how much."));

    report.scenarios.forEach((entry, index) => renderScenario(entry, data.plots[index], index));
  }

  window.bouncecheckAnimations = [];

  // The animation of a scenario: every simulator that ran to the end (a
  // failed or skipped one shows no ball; its reason is listed beside).
  function animation(section, entry, plots, index) {
    const balls = [], absent = [];
    entry.simulators.forEach((r, i) => {
      const plot = plots && plots.simulators[i];
      if (r.status === "ok" && plot && plot.path.t.length)
        balls.push({ name: r.simulator, colour: colour(r.simulator), path: plot.path, contacts: plot.contacts });
      else absent.push({ name: r.simulator, reason: r.status + (r.reason ? ": " + r.reason : "") });
    });
    const box = el("div", { class: "animation", id: "animation-" + index });
    section.appendChild(box);
    window.bouncecheckAnimations[index] =
      BouncecheckAnimation.create(box, { scenario: entry.scenario, balls: balls, absent: absent });
  }

  function renderScenario(entry, plots, index) {
    const s = entry.scenario;
    const section = el("section", { class: "scenario", id: "scenario-" + index });
    page.appendChild(section);
    section.appendChild(el("h2", {}, [s.name + " ", el("a", { href: "#contents", class: "up" }, "↑ contents")]));
    section.appendChild(el("p", { class: "params" },
      s.dim + "D, room " + vec(s.room) + " m, radius " + num(s.radius) + " m, start " + vec(s.position) +
      " m, velocity " + vec(s.velocity) + " m/s, gravity " + vec(s.gravity) + " m/s², alpha " + s.alpha +
      ", beta " + s.beta + ", dt " + s.dt + " s, duration " + s.duration + " s (" + s.file + ")"));
    if (plots) animation(section, entry, plots, index);

    // Simulators that ran (ok or failed) and have a recorded plot, in the report's order.
    const ran = [];
    entry.simulators.forEach((r, i) => {
      const plot = plots && plots.simulators[i];
      if (r.status !== "skipped" && plot) ran.push({ name: r.simulator, result: r, plot: plot });
    });
    const restOf = (name) => { const r = entry.simulators.find((x) => x.simulator === name); return r ? r.rest_time : null; };
    const grid = el("div", { class: "grid" });
    section.appendChild(grid);
    const id = (kind) => "plot-" + index + "-" + kind;
    if (plots) {
      pathPlot(grid, id("path"), s, ran);
      apexPlot(grid, id("apex"), plots, ran);
      heightPlot(grid, id("height"), plots.vertical, ran);
      distancePlot(grid, id("divergence"), "divergence", "Divergence from the reference (largest per window)", ran, REFERENCE, "divergence", restOf(REFERENCE));
      distancePlot(grid, id("error"), "error", "Error against exact (largest per window)", ran, EXACT, "error", restOf(EXACT));
      dampingPlot(grid, id("normal"), "normal", "Normal coefficient per contact", s, ran, "normal", "alpha", s.alpha);
      dampingPlot(grid, id("tangential"), "tangential", "Tangential retention per contact", s, ran, "tangential", "beta", s.beta);
      section.appendChild(el("p", { class: "note" },
        "Contacts measured for damping: before the simulator's rest and faster than 30 |g| dt, as the damping verdict counts them."));
    }

    const checks = entry.simulators.flatMap((r) => (r.comparison ? r.comparison.thresholds : []).map((t) => ({ r: r, t: t })));
    const exceeded = checks.filter((x) => !x.t.passed);
    const row = (x) => [x.r.simulator, x.t.metric, num(x.t.measured, 4), num(x.t.limit, 4),
                        x.t.passed ? { text: "held", cls: "pass" } : { text: "exceeded", cls: "fail" }];
    section.appendChild(el("h3", {}, "Threshold verdicts"));
    if (!checks.length) section.appendChild(el("p", {}, "No threshold is set for this scenario."));
    else {
      if (exceeded.length) section.appendChild(table(["simulator", "metric", "measured", "limit", "verdict"], exceeded.map(row)));
      section.appendChild(el("details", {}, [
        el("summary", {}, checks.length - exceeded.length + " of " + checks.length + " held: show every check"),
        table(["simulator", "metric", "measured", "limit", "verdict"], checks.map(row))]));
    }

    const notRun = entry.simulators.filter((r) => r.status !== "ok");
    if (notRun.length) {
      section.appendChild(el("h3", {}, "Skipped and failed simulators"));
      section.appendChild(table(["simulator", "status", "reason"], notRun.map((r) => [r.simulator, { text: r.status, cls: r.status === "failed" ? "fail" : "skip" }, r.reason || "-"])));
    }

    const withSettings = entry.simulators.filter((r) => r.settings && r.settings.length);
    if (withSettings.length) {
      section.appendChild(el("h3", {}, "Engine settings"));
      for (const r of withSettings) {
        section.appendChild(el("details", {}, [
          el("summary", {}, r.simulator + (r.origin ? " — " + r.origin : "") + " (" + r.settings.length + " settings)"),
          table(["setting", "value", "why"], r.settings.map((st) => [st.key, st.value, st.why]), "settings")]));
      }
    }
  }

  // ------------------------------------------------------------ sweep report

  function renderSweep() {
    const sweep = data.sweep;
    page.appendChild(el("h1", {}, "bouncecheck sweep: " + sweep.scenario));
    page.appendChild(el("p", { class: "lede" },
      "Error: " + sweep.error_metric + ". Cost: run time per simulated second, the fastest of " +
      sweep.parameters.repeat + " timed run(s) that record nothing. Each simulator ran at every dt; its convergence " +
      "order is the least-squares slope of log error against log dt. Circled: the Pareto front (no other run is both cheaper and more accurate)."));
    const byEngine = {};
    for (const row of sweep.rows) (byEngine[row.engine] = byEngine[row.engine] || []).push(row);
    // A sweep run with --no-timings has no cost: its errors are plotted against dt.
    const timed = sweep.rows.some((r) => r.sec_per_sim_sec > 0);
    const cost = (r) => (timed ? r.sec_per_sim_sec : r.dt);
    const usable = (r) => r.status === "ok" && r.error > 0 && cost(r) > 0;
    // Errors at round-off (an event-driven scheme's, about 1e-13 m) would set
    // the scale and squash every engine into one band: the axis starts a
    // factor 3 below the smallest error above kRoundOff, and smaller errors
    // are drawn on that edge as down-pointing triangles, their value in the hover.
    const kRoundOff = 1e-10;
    const above = sweep.rows.filter(usable).map((r) => r.error).filter((e) => e >= kRoundOff);
    const floor = above.length ? Math.min(...above) / 3 : null;
    const shown = (e) => (floor !== null && e < floor ? floor : e);
    const clipped = (e) => floor !== null && e < floor;
    const traces = Object.entries(byEngine).map(([name, rows]) => {
      const ok = rows.filter(usable);
      return { x: ok.map(cost), y: ok.map((r) => shown(r.error)),
               customdata: ok.map((r) => r.error),
               text: ok.map((r) => "dt = " + r.dt + (clipped(r.error) ? " (round-off: below the axis)" : "")),
               mode: "lines+markers", name: name, line: { color: colour(name) },
               marker: { symbol: ok.map((r) => (clipped(r.error) ? "triangle-down" : "circle")), size: 8 },
               hovertemplate: "%{text}<br>" + (timed ? "cost %{x:.3g} s/s" : "dt %{x:.3g} s") +
                 "<br>error %{customdata:.3g} m<extra>" + name + "</extra>" };
    });
    const front = sweep.rows.filter((r) => r.pareto).sort((a, b) => a.sec_per_sim_sec - b.sec_per_sim_sec);
    traces.push({ x: front.map((r) => r.sec_per_sim_sec), y: front.map((r) => shown(r.error)),
                  text: front.map((r) => r.engine + ", dt = " + r.dt), mode: "lines+markers", name: "Pareto front",
                  line: { color: "#000", dash: "dot", width: 1 }, marker: { symbol: "circle-open", size: 16, color: "#000" },
                  hovertemplate: "%{text}<extra>Pareto front</extra>" });
    const errorsShown = sweep.rows.filter(usable).map((r) => shown(r.error));
    const yRange = floor === null || !errorsShown.length ? undefined
      : [Math.log10(floor), Math.log10(Math.max(...errorsShown)) + 0.15];
    const grid = el("div", { class: "grid" });
    page.appendChild(grid);
    addPlot(grid, "plot-sweep-work-precision", "work-precision",
            timed ? "Work-precision: error against cost" : "Error against dt (run with --no-timings: no cost)", traces, {
      xaxis: axisTitle(timed ? "cost (s of run time per simulated s)" : "dt (s)", { type: "log", exponentformat: "power" }),
      yaxis: axisTitle("error against exact (m)", Object.assign({ type: "log", exponentformat: "power" },
                                                               yRange ? { range: yRange } : {})),
    }, true);
    if (errorsShown.some((e, i) => e !== sweep.rows.filter(usable)[i].error))
      page.appendChild(el("p", { class: "note" }, "Triangles on the lower edge: errors below " + num(floor, 2) +
        " m, at round-off (hover for the value); the axis leaves them out so the engines can be told apart."));
    page.appendChild(el("h3", {}, "Observed convergence orders"));
    page.appendChild(table(["simulator", "fitted order", "dts in the fit"],
      sweep.orders.map((o) => [o.engine, o.order === null ? "-" : num(o.order, 3), String(o.points)])));
    page.appendChild(el("h3", {}, "Every run"));
    page.appendChild(table(["simulator", "dt (s)", "status", "error (m)", "bounce error", "ns per step", "cost (s/s)", "Pareto"],
      sweep.rows.map((r) => [r.engine, String(r.dt),
                             r.status === "ok" ? "ok" : { text: r.status + (r.reason ? ": " + r.reason : ""), cls: r.status === "failed" ? "fail" : "skip" },
                             num(r.error, 3), num(r.bounce_error, 3), num(r.ns_per_step, 3), num(r.sec_per_sim_sec, 3), r.pareto ? "yes" : ""])));
  }

  if (data.kind === "sweep") renderSweep(); else renderRun();
})();
