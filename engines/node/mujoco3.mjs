// MuJoCo 3 (npm mujoco-js, the official WebAssembly build; f64) as a
// bouncecheck engine: `node mujoco3.mjs` speaks bouncecheck-external/1
// (docs/external.md) through host/protocol.mjs.
//
// The world is the compiled `mujoco` adapter's (engines/mujoco/mujoco_adapter.cpp,
// MuJoCo 2.2.2; docs/engines.md): a sphere on slide joints (x, y, z in 3D;
// x and z in 2D, so the scenario's (x, y) is MuJoCo's (x, z) and the ball
// cannot leave y = 0), a ball joint (2D: a hinge about y) when rotation is
// free, and the room as planes on the world body. Slides come first, so
// qpos[i] and qvel[i] are the scenario's axis i in both dimensions.
//
// MuJoCo has no restitution: a contact row's reference acceleration is
// aref = -b v - k x (solref, direct format (-k, -b)), reached through the
// impedance d (solimp). The chosen law is the compiled adapter's one-step
// damper: b h = 1 + alpha - k h^2 / 2 (h the mj_step), so the step that finds
// the ball inside a wall turns its normal velocity from -u to alpha u whatever
// the depth (no dependence on where within a step the ball crossed the wall),
// plus a weak anchor spring k h^2 = 1e-4 (1 - alpha) that holds a resting
// ball up against the 1e-4 of gravity the impedance leaks. An engine step is
// inner_steps mj_steps of h = dt / inner_steps, so that the ball, found only
// once inside a wall, never sinks deeper than the skin. Every choice is an
// own key of [engines.<name>] whose default is the chosen value; each one's
// MuJoCo default is named in ownKeys and measured in the settings' `why`.
//
// Per-contact mode: mj_step is split. mj_step1 runs collision at the step's
// starting position and builds the constraint rows; for each ball-wall contact
// in d.contact that was not there at the previous step and that the law
// counts (the ball moves into the wall), every slide velocity but the wall's
// normal is scaled by beta in d.qvel, mj_fwdVelocity recomputes the
// velocity-dependent terms, and mj_step2 solves and integrates from the
// scaled velocity. This is the compiled adapter's hook, call for call.
import { serve, ScenarioError, roomWalls, maxBallSpeed, movesIntoWall,
  ownKey, nonNegative, positive, count0, count1, trueOrFalse, oneOf, either, numbers } from './host/protocol.mjs';

const mjMINIMP = 0.0001, mjMAXIMP = 0.9999;  // engine_core_constraint.c's impedance clamp

const ownKeys = {
  solref: '"damper" (chosen: one-step damper, direct (-k, -b)) or [timeconst, dampratio] / [-k, -b] as MuJoCo reads it; MuJoCo default [0.02, 1]',
  solimp: '[dmin, dmax, width, midpoint, power]; chosen [0.9999, 0.9999, 0.001, 0.5, 2] (flat), MuJoCo default [0.9, 0.95, 0.001, 0.5, 2]',
  damper_anchor: 'the damper\'s anchor spring, k h^2 = damper_anchor (1 - alpha); chosen 1e-4, 0 = no spring (a pure damper)',
  impedance_correction: 'divide solref by 1 / (d + (1 - d) A~/A) so the ball feels exactly k and b (A~/A = 1 in 3D, 2/3 in 2D); chosen true',
  condim: '"auto" (chosen: 1 when mu = 0, else 3) or 1, 3, 4, 6; MuJoCo default 3',
  wall_friction: '"ball" (chosen: the walls carry the ball\'s mu) or a number; MuJoCo default 1 (a contact takes the larger geom mu)',
  cone: '"elliptic" (chosen) or "pyramidal" (MuJoCo default)',
  integrator: '"Euler" (chosen, MuJoCo default), "implicit", "implicitfast" or "RK4"',
  timestep: '"dt" (chosen: opt.timestep = dt / inner_steps) or seconds; MuJoCo default 0.002',
  gravity: '"scenario" (chosen) or a 3-vector in MuJoCo\'s frame; MuJoCo default [0, 0, -9.81]',
  impratio: 'opt.impratio; chosen 1 (MuJoCo default)',
  noslip_iterations: 'opt.noslip_iterations; chosen 0 (MuJoCo default)',
  margin: 'geom margin (m); chosen 0 (MuJoCo default)',
  ball_mass: 'kg; chosen 1, 0 = MuJoCo\'s geom density 1000',
  beta_hook: '"split" (chosen: beta between mj_step1 and mj_step2) or "after" (after mj_step, judged on the velocity the step started from)',
  fail_on_warning: 'a MuJoCo warning (a NaN reset, a full buffer) fails the run; chosen true',
  inner_steps: '"auto" (chosen: mj_steps per engine step so that one travels at most 0.8 max(2 mm, 2% r) at the energy bound\'s speed) or an integer >= 1 (1: one mj_step per step, as the compiled mujoco)',
};

const num = (x) => String(x);  // JS numbers print in shortest round-trip form

// ---- The own keys, checked ----

function tuning(s) {
  return {
    solref: ownKey(s, 'solref', 'damper', either(oneOf('damper'), numbers(2))),
    solimp: ownKey(s, 'solimp', [mjMAXIMP, mjMAXIMP, 0.001, 0.5, 2], numbers(5)),
    damper_anchor: ownKey(s, 'damper_anchor', 1e-4, nonNegative),
    impedance_correction: ownKey(s, 'impedance_correction', true, trueOrFalse),
    condim: ownKey(s, 'condim', 'auto', oneOf('auto', 1, 3, 4, 6)),
    wall_friction: ownKey(s, 'wall_friction', 'ball', either(oneOf('ball'), nonNegative)),
    cone: ownKey(s, 'cone', 'elliptic', oneOf('elliptic', 'pyramidal')),
    integrator: ownKey(s, 'integrator', 'Euler', oneOf('Euler', 'implicit', 'implicitfast', 'RK4')),
    timestep: ownKey(s, 'timestep', 'dt', either(oneOf('dt'), positive)),
    gravity: ownKey(s, 'gravity', 'scenario', either(oneOf('scenario'), numbers(3))),
    impratio: ownKey(s, 'impratio', 1, positive),
    noslip_iterations: ownKey(s, 'noslip_iterations', 0, count0),
    margin: ownKey(s, 'margin', 0, nonNegative),
    ball_mass: ownKey(s, 'ball_mass', 1, nonNegative),
    beta_hook: ownKey(s, 'beta_hook', 'split', oneOf('split', 'after')),
    fail_on_warning: ownKey(s, 'fail_on_warning', true, trueOrFalse),
    inner_steps: ownKey(s, 'inner_steps', 'auto', either(oneOf('auto'), count1)),
  };
}

// ---- The contact law (engines/mujoco/mujoco_adapter.cpp, contact_parameters) ----

// The flat impedance MuJoCo uses for a contact (getimpedance: dmin = dmax or a
// zero width give their mean), or dmax when it varies with depth.
function impedance(solimp) {
  const lo = Math.min(Math.max(solimp[0], mjMINIMP), mjMAXIMP);
  const hi = Math.min(Math.max(solimp[1], mjMINIMP), mjMAXIMP);
  return lo === hi || solimp[2] <= 1e-15 ? 0.5 * (lo + hi) : hi;
}

// How many mj_steps make one engine step: MuJoCo finds a contact only once
// the ball is inside the wall (no speculative contact: a row exists only for
// distance < margin - gap, which is also the origin of its spring), so the
// one-step damper lets the ball sink up to one mj_step's travel, |v| h.
function innerSteps(s, t) {
  const skin = Math.max(0.002, 0.02 * s.radius);
  const travel = maxBallSpeed(s) * s.dt;
  const auto = Math.max(1, Math.ceil(travel / (0.8 * skin) - 1e-9));
  return { n: t.inner_steps === 'auto' ? auto : t.inner_steps, auto, skin, travel };
}

function contactLaw(s, t, h) {
  const d = impedance(t.solimp);
  // A~/A: MuJoCo's diagonal estimate of the contact's inverse mass over the
  // real one. 3D: 1. 2D: 2/3 (the mean of the translational inverse
  // inertias over three axes, one of them locked).
  const ratio = s.dimension === 3 ? 1 : 2 / 3;
  const factor = t.impedance_correction ? 1 / (d + (1 - d) * ratio) : 1;
  if (t.solref !== 'damper') return { solref: t.solref, factor, rule: 'given' };
  const anchor = t.damper_anchor * (1 - s.alpha);
  const k = anchor / (h * h) / factor;
  const b = (1 + s.alpha - anchor / 2) / h / factor;
  return { solref: [-k, -b], k, b, anchor, factor, derived: (1 + s.alpha) / h, rule: 'damper' };
}

// ---- The model ----

function modelXml(s, t, h, law, mu, wallMu, condim, freeRotation) {
  const d = s.dimension;
  const axis = (i) => (d === 3 ? i : i === 0 ? 0 : 2);  // scenario axis -> MuJoCo axis
  const g = [0, 0, 0];
  for (let i = 0; i < d; ++i) g[axis(i)] = s.gravity[i];
  const gravity = t.gravity === 'scenario' ? g : t.gravity;
  const timestep = t.timestep === 'dt' ? h : t.timestep;
  let xml = '<mujoco model="bouncecheck">\n'
    + '  <compiler angle="radian" inertiafromgeom="true" autolimits="true"/>\n'
    + `  <option timestep="${num(timestep)}" gravity="${gravity.map(num).join(' ')}" integrator="${t.integrator}"`
    + ` cone="${t.cone}" impratio="${num(t.impratio)}" solver="Newton" iterations="100" tolerance="1e-8"`
    + ` noslip_iterations="${t.noslip_iterations}" density="0" viscosity="0" wind="0 0 0"/>\n`
    + '  <default>\n'
    + `    <geom condim="${condim}" friction="${num(mu)} 0 0" solref="${law.solref.map(num).join(' ')}"`
    + ` solimp="${t.solimp.map(num).join(' ')}" margin="${num(t.margin)}" gap="0" solmix="1" priority="0"`
    + ' contype="1" conaffinity="1"/>\n'
    + '    <joint damping="0" armature="0" frictionloss="0" stiffness="0"/>\n'
    + '  </default>\n'
    + '  <worldbody>\n';
  roomWalls(s).forEach((w, n) => {
    const p = [0, 0, 0], normal = [0, 0, 0];
    p[axis(w.axis)] = w.offset;
    normal[axis(w.axis)] = -w.side;  // into the room
    xml += `    <geom name="wall${n}" type="plane" size="0 0 1" pos="${p.map(num).join(' ')}"`
      + ` zaxis="${normal.map(num).join(' ')}" friction="${num(wallMu)} 0 0"/>\n`;
  });
  xml += '    <body name="ball" pos="0 0 0">\n';
  for (let a = 0; a < 3; ++a) {
    if (d === 2 && a === 1) continue;
    xml += `      <joint name="slide${a}" type="slide" axis="${a === 0 ? 1 : 0} ${a === 1 ? 1 : 0} ${a === 2 ? 1 : 0}"/>\n`;
  }
  if (freeRotation) xml += d === 3 ? '      <joint name="spin" type="ball"/>\n' : '      <joint name="spin" type="hinge" axis="0 1 0"/>\n';
  xml += `      <geom name="ball" type="sphere" size="${num(s.radius)}"${t.ball_mass > 0 ? ` mass="${num(t.ball_mass)}"` : ''}/>\n`;
  xml += '    </body>\n  </worldbody>\n</mujoco>\n';
  return xml;
}

const WARNINGS = ['INERTIA', 'CONTACTFULL', 'CNSTRFULL', 'VGEOMFULL', 'BADQPOS', 'BADQVEL', 'BADQACC', 'BADCTRL'];

// ---- The adapter ----

let library = null;  // one WebAssembly instance for both dimensions
let models = 0;

// The last model compiled, kept for the next run of the same MJCF (a sweep's
// repeats, a session's repeated scenario): compiling costs about 1.4 ms, 3% of
// a seed run's steps at dt 1e-3. mj_step reads the model and never writes it,
// and this file writes none of its fields, so a run cannot see the run before
// (a session's rows for the same scenario twice are identical, measured).
let lastModel = null;  // { xml, m }
function compiledModel(mj, xml) {
  if (lastModel?.xml === xml) return lastModel.m;
  const file = `/bouncecheck-${++models}.xml`;
  mj.FS.writeFile(file, xml);
  let m;
  try {
    m = mj.MjModel.loadFromXML(file);
  } catch (e) {
    // mj_loadXML throws an mjCError, whose text this build does not export.
    throw new ScenarioError(`MuJoCo could not compile the model (${e?.name || e}); the MJCF was:\n${xml}`);
  } finally {
    mj.FS.unlink(file);
  }
  lastModel?.m.delete();
  lastModel = { xml, m };
  return m;
}

const adapter = {
  name: 'mujoco3',
  dimensions: [2, 3],
  precision: 'f64',
  packages: () => ['mujoco-js'],
  ownKeys,
  async load() {
    if (!library) {
      const { default: loadMujoco } = await import('mujoco-js');
      // MuJoCo's warnings (mju_warning) print through Emscripten's `out`,
      // which is console.log, i.e. standard output: they would land in the
      // middle of the trajectory. Both streams go to standard error.
      const toStderr = (text) => process.stderr.write(`mujoco-js: ${text}\n`);
      library = loadMujoco({ print: toStderr, printErr: toStderr });
    }
    return library;
  },
  version: (mj) => `MuJoCo ${mj.mj_versionString()}`,
  build(mj, s, settings) {
    const d = s.dimension;
    const t = tuning(s);
    if (s.engine.ccd === true) throw new ScenarioError('MuJoCo has no continuous collision detection: use substeps');
    const perContact = s.engine.tangential_model === 'per-contact';
    const mu = perContact ? 0 : s.engine.friction;  // the shared keys are checked by host/protocol.mjs
    const condim = t.condim === 'auto' ? (mu > 0 ? 3 : 1) : t.condim;
    const wallMu = t.wall_friction === 'ball' ? mu : t.wall_friction;
    const freeRotation = s.engine.rotation !== 'locked';
    const inner = innerSteps(s, t);
    const h = s.dt / inner.n;
    const law = contactLaw(s, t, h);
    const xml = modelXml(s, t, h, law, mu, wallMu, condim, freeRotation);

    const m = compiledModel(mj, xml);
    const data = new mj.MjData(m);
    // Views into the WebAssembly memory, taken once (each property read
    // makes a new view); taken again if the memory ever grows (a grown
    // memory detaches the old buffer: length 0).
    let qpos = data.qpos, qvel = data.qvel;
    const refresh = () => { qpos = data.qpos; qvel = data.qvel; };
    for (let i = 0; i < d; ++i) { qpos[i] = s.position[i]; qvel[i] = s.velocity[i]; }

    // Geom ids: the walls are geoms 0 .. 2d-1 in the order of roomWalls(s),
    // the ball geom the last.
    const walls = roomWalls(s);
    const ballGeom = m.ngeom - 1;
    let touching = 0;  // bit per wall: a ball-wall contact at the previous step
    const stats = { newContacts: 0, betaApplied: 0, touchingSteps: 0, maxContacts: 0, contactReads: 0 };

    // The walls the ball holds a contact with, from d.contact (a vector copy
    // and one handle per contact). A resting ball holds its floor contact step after step: d.contact is
    // read only when the contacts may have changed. `near`: the walls whose
    // plane the sphere is within margin (+ 1e-9) of, the test mjc_PlaneSphere
    // makes, so MuJoCo's contacts are a subset of them; if there are as many
    // contacts as near walls and those are the walls touched at the previous
    // step, the contacts are those walls.
    // (In the "after" hook d.contact is from the step's start, qpos from its
    // end: no shortcut.)
    const reach = t.margin + 1e-9;
    const shortcut = t.beta_hook === 'split';
    const contactWalls = () => {
      const ncon = data.ncon;
      if (ncon === 0) return 0;
      if (ncon > stats.maxContacts) stats.maxContacts = ncon;
      let near = 0, count = 0;
      for (let w = 0; w < walls.length; ++w) {
        const { axis, side, offset } = walls[w];
        if ((side < 0 ? qpos[axis] - offset : offset - qpos[axis]) - s.radius <= reach) { near |= 1 << w; ++count; }
      }
      if (shortcut && near === touching && count === ncon) return near;
      ++stats.contactReads;
      let now = 0;
      const list = data.contact;
      for (let i = 0; i < ncon; ++i) {
        const c = list.get(i);
        if (!c.exclude) {
          const other = c.geom1 === ballGeom ? c.geom2 : c.geom2 === ballGeom ? c.geom1 : -1;
          if (other >= 0 && other < walls.length) now |= 1 << other;
        }
        c.delete();
      }
      list.delete();
      return now;
    };
    // Beta on every slide velocity but the wall's normal, for each contact
    // that starts and that the law counts; `judged` is the velocity the
    // law's condition reads. Returns whether qvel changed.
    const applyBeta = (judged) => {
      const now = contactWalls();
      let scaled = false;
      if (now) {
        stats.touchingSteps++;
        for (let w = 0; w < walls.length; ++w) {
          if (!((now >> w) & 1) || ((touching >> w) & 1)) continue;
          stats.newContacts++;
          const { axis, side } = walls[w];
          if (!movesIntoWall(judged[axis], s.gravity[axis], side)) continue;
          for (let i = 0; i < d; ++i) if (i !== axis) qvel[i] *= s.beta;
          stats.betaApplied++;
          scaled = true;
        }
      }
      touching = now;
      return scaled;
    };

    const totalSteps = s.steps * s.engine.substeps * inner.n;
    let steps = 0;
    const before = new Float64Array(d);
    const checkWarnings = () => {
      const list = data.warning;
      const found = [];
      for (let i = 0; i < WARNINGS.length; ++i) {
        const w = list.get(i);
        if (w.number > 0) found.push(`mjWARN_${WARNINGS[i]} (${w.number}x, info ${w.lastinfo})`);
        w.delete();
      }
      list.delete();
      return found;
    };
    const fail = () => {
      const found = checkWarnings();
      throw new ScenarioError(`MuJoCo warning at step ${steps}: ${found.join(', ') || 'the clock went back (mj_step reset mjData)'}`
        + (found.some((w) => /BADQ/.test(w)) ? '; MuJoCo reset the ball to its start' : ''));
    };
    const timestep = m.opt.timestep;

    report(mj, s, t, law, m, { mu, wallMu, condim, freeRotation, perContact, inner, settings });

    let step;
    if (perContact && t.beta_hook === 'split') {
      step = () => {
        mj.mj_step1(m, data);
        if (qvel.length === 0) refresh();
        if (applyBeta(qvel)) mj.mj_fwdVelocity(m, data);
        mj.mj_step2(m, data);
      };
    } else if (perContact) {
      step = () => {
        if (qvel.length === 0) refresh();
        for (let i = 0; i < d; ++i) before[i] = qvel[i];
        mj.mj_step(m, data);
        applyBeta(before);
      };
    } else {
      step = () => mj.mj_step(m, data);
    }
    const n = inner.n;
    return {
      step() {
        for (let i = 0; i < n; ++i) step();
        steps += n;
        if (t.fail_on_warning) {
          // mj_step resets mjData (time 0) on a NaN or a value beyond 1e10,
          // with a warning only: the clock going back is the cheap sign.
          if (data.time < (steps - 0.5) * timestep) fail();
          if (steps === totalSteps && checkWarnings().length) fail();
        }
      },
      read(out) {
        if (qpos.length === 0) refresh();
        for (let i = 0; i < d; ++i) { out[i] = qpos[i]; out[d + i] = qvel[i]; }
      },
      free() {
        if (process.env.BOUNCECHECK_MUJOCO3_STATS) process.stderr.write(`mujoco3 stats: ${JSON.stringify(stats)}\n`);
        data.delete();  // the model stays for the next run (compiledModel)
      },
      stats,
    };
  },
};

function report(mj, s, t, law, m, { mu, wallMu, condim, freeRotation, perContact, inner, settings }) {
  // Measured numbers below: docs in findings (seed-3d / seed-2d, exact's in brackets).
  const add = (k, v, why) => settings.add(k, v, why);
  const d = s.dimension;
  const chosenSolimp = t.solimp.join() === [mjMAXIMP, mjMAXIMP, 0.001, 0.5, 2].join();
  add('inner_steps', `${inner.n}${t.inner_steps === 'auto' ? ' (auto)' : ` (given; auto would be ${inner.auto})`}`,
    `mj_steps of dt / ${inner.n} per engine step. MuJoCo has no speculative contact: a row exists only once the ball is within the margin, which is also its spring's origin, so the damper turns the ball up to one mj_step's travel inside a wall; `
    + `a step of dt travels up to ${num(+inner.travel.toPrecision(4))} m at the energy bound's ${num(+maxBallSpeed(s).toPrecision(4))} m/s, against the skin max(2 mm, 2% r) = ${num(inner.skin)} m. `
    + 'One mj_step per step (the compiled mujoco): 6.18 mm deep on seed-3d at dt 0.03 (auto: 0.33 mm), 4.33 mm on earth-drop at dt 1e-3 (auto: 0.17 mm)');
  add('axes', d === 3 ? 'scenario (x, y, z) = MuJoCo (x, y, z)' : 'scenario (x, y) = MuJoCo (x, z); no y joint',
    d === 3 ? 'MuJoCo is 3D, z up' : 'the ball has slide joints on x and z only: it cannot leave y = 0');
  add('timestep', t.timestep === 'dt' ? `${num(m.opt.timestep)} s (opt.timestep = dt / inner_steps)` : `${num(m.opt.timestep)} s (given)`,
    'mj_step advances opt.timestep whatever dt is. MuJoCo\'s 0.002 s: at dt 1e-3 the damper (b h = 3.6) is unstable, mjWARN_BADQACC at t = 3.44 s and the run fails; at dt 0.03 the scene runs at 0.73x, first floor contact at 7.71 s (5.656) with restitution 0.32');
  add('gravity', t.gravity === 'scenario' ? 'the scenario\'s (MuJoCo frame)' : `(${t.gravity.join(', ')}) (given)`,
    'MuJoCo\'s default (0, 0, -9.81) is 100x the seeds\': first floor contact at 0.325 s (5.656)');
  add('integrator', t.integrator, 'MuJoCo\'s default Euler (semi-implicit: v += a h, then x += v h): the damper is written for one Euler update per mj_step. RK4 re-runs collision and the damper at its stages: the floor does not bounce (restitution 0.004, at rest from 5.64 s, friction mode). implicitfast: Euler to 1e-12'
    + (perContact && t.beta_hook === 'split' ? '. The split step (mj_step1 / mj_step2) integrates with Euler whatever this says' : ''));
  if (law.rule === 'damper') {
    add('contact.solref', `direct (${num(law.solref[0])}, ${num(law.solref[1])}): k = ${num(-law.solref[0])} 1/s^2, b = ${num(-law.solref[1])} 1/s`,
      'one-step damper: b h = 1 + alpha - k h^2 / 2 (divided by the impedance factor) turns the normal velocity from -u to alpha u in the mj_step that finds the ball inside a wall, whatever the depth (a spring lasting several steps gives a restitution that depends on where in a step the ball crosses); '
      + `anchor k h^2 = ${num(t.damper_anchor)} (1 - alpha) = ${num(law.anchor)} holds a resting ball up against the 1e-4 of gravity the impedance leaks. MuJoCo's default solref (0.02, 1) is critically damped: second apex 0.0589 m (0.4590), at rest from 6.69 s (34.03)`);
  } else {
    add('contact.solref', `(${law.solref.map(num).join(', ')}) (given)`, 'MuJoCo reads a positive pair as (time constant, damping ratio), a negative one as (-k, -b)');
  }
  add('contact.solimp', `(${t.solimp.map(num).join(', ')})`, chosenSolimp
    ? 'flat impedance d = 0.9999 (mjMAXIMP): the row reaches 99.99% of aref at any depth. MuJoCo\'s default (0.9, 0.95, 0.001, 0.5, 2) lets 5-10% of gravity and of the damper through: seed-2d floor restitution 0.736, second apex 0.5322 m (0.6187), at rest from 27.77 s (38.04)'
    : 'given');
  add('contact.impedance_factor', num(law.factor), t.impedance_correction
    ? `solref divided by 1 / (d + (1 - d) A~/A), A~/A = ${d === 3 ? '1 (3D)' : '2/3 (2D: one of three axes locked)'}: the ball feels exactly k and b. Without it the 2D side walls measure 0.80006 (0.80001)`
    : 'off: solref as given to an ideal (d = 1) constraint');
  add('contact.margin', num(t.margin), 'MuJoCo\'s default: a contact row exists from distance < margin, and a margin starts the law before the ball reaches the wall');
  add('contact.condim', condim, condim === 1 ? 'frictionless (per-contact mode or mu = 0). MuJoCo\'s default 3 with its wall friction 1: first apex 0.6012 m (0.6996), the t = 0 back-wall contact keeps 0.48 of the tangential speed (0.99)'
    : 'normal and two sliding directions (Coulomb)');
  add('contact.friction', `ball ${num(mu)}, walls ${num(wallMu)}`, perContact ? 'per-contact mode: mu = 0, beta applied by the step hook'
    : 'Coulomb mu from [engines] friction on both geoms (a contact takes the larger). MuJoCo\'s default wall friction 1 makes every contact\'s mu 1: first apex 0.6029 m (0.6993 with mu 0.0129), t = 0 retention 0.49 (0.99)');
  add('contact.cone', t.cone, 'elliptic is Coulomb\'s cone. MuJoCo\'s default pyramid (friction mode, seed-3d, mu 0.0129): the t = 0 back-wall contact keeps vz, first apex 0.7038 m (elliptic 0.6993)');
  add('contact.impratio', num(t.impratio), 'MuJoCo\'s default; it scales the friction rows\' regulariser only');
  add('solver', `Newton, 100 iterations, tolerance 1e-8, noslip ${t.noslip_iterations}`, 'MuJoCo\'s defaults, written out');
  add('walls', `${2 * d} planes on the world body at x_i = 0 and x_i = room_i, normals inward`, 'a plane is a half-space: a ball however deep still gets a contact');
  add('ball', `sphere r = ${num(s.radius)} m, ${t.ball_mass > 0 ? `mass ${num(t.ball_mass)} kg` : 'density 1000'}`, 'the law is per unit mass (direct solref are accelerations)');
  add('joints', `slides on ${d === 3 ? 'x, y, z' : 'x, z'}${freeRotation ? (d === 3 ? ' + ball joint' : ' + hinge about y') : ' (rotation locked)'}; damping, armature, frictionloss, stiffness 0`,
    'MuJoCo\'s defaults, written out');
  add('fluid', 'density 0, viscosity 0, wind 0', 'MuJoCo\'s defaults: no drag');
  add('sleeping', 'none', 'MuJoCo 3.3.8 has no sleeping (no such flag in mjtDisableBit / mjtEnableBit)');
  add('ccd', 'none', 'sphere-plane collision is analytic and discrete; inner_steps or substeps shorten the travel');
  add('warnings', t.fail_on_warning ? 'fail the run' : 'ignored',
    'mj_step resets mjData to its start on a NaN or a value beyond 1e10 with a warning only (seen: the clock going back); the warning text goes to stderr (Emscripten prints it with console.log, i.e. into the trajectory, unless print is redirected)');
  add('tangential_model', perContact
    ? `per-contact: beta = ${num(s.beta)} on d.qvel ${t.beta_hook === 'split' ? 'between mj_step1 and mj_step2 of the mj_step whose collision first finds the contact (then mj_fwdVelocity)' : 'after mj_step, judged on the velocity the step started from'}`
    : `friction: Coulomb mu = ${num(mu)}`,
  perContact ? 'every slide velocity but the wall\'s normal, once when a ball-wall contact in d.contact is new and the ball moves into the wall (the compiled mujoco\'s hook)' : 'the scenario\'s [engines] table');
}

export default adapter;
await serve(adapter);
