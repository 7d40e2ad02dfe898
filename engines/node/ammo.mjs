// ammo.js (npm ammo.js 0.0.10: Bullet 2.82 compiled to asm.js by
// Emscripten, f32) as a bouncecheck simulator: protocol
// bouncecheck-external/1 through host/protocol.mjs (`node ammo.mjs`, or
// `node ammo.mjs --session`).
//
// The package was built from the kripken/ammo.js tree of late 2014 (its
// package.json says 0.0.10 from commit 12d0050, 2014-09; its bindings include
// getSolverInfo, added in commit 5881fcc, 2014-10), whose bullet/ folder is
// Bullet 2.82 (BT_BULLET_VERSION 282, LinearMath/btScalar.h:31, unchanged
// there since 2014-04). Line numbers below are of that tree's
// bullet/src. How a step goes (btDiscreteDynamicsWorld.cpp:470-517,
// internalSingleStepSimulation): predicted motion, predictive (CCD)
// contacts, the narrow phase on the positions the last step left, the
// sequential-impulse solve, then the position update. A contact point exists
// once the gap is under the manifold's breaking threshold (0.02 x the
// sphere's angular motion disc: 1.73 mm for r = 5 cm); the solver takes the
// points whose gap is under the contact processing threshold (the smaller
// of the two bodies', BT_LARGE_FLOAT by default;
// btSequentialImpulseConstraintSolver.cpp:824). For a point with gap d > 0 it
// asks for the normal velocity alpha u - d / dt (lines 666, 704, 713-717):
// a speculative point eats d / dt of the bounce. For an overlap p it asks for
// alpha u, plus erp p / dt unless split impulse takes the overlap (lines
// 707-737). There is no restitution velocity threshold in 2.82 (Bullet 3's
// m_restitutionVelocityThreshold) and m_lifeTime is never read by the solver
// (m_restingContactRestitutionThreshold: "unused as of 2.81",
// btContactSolverInfo.h). Predictive CCD points carry restitution 0
// (btDiscreteDynamicsWorld.cpp:959).
//
// So a ball bounces with exactly alpha once only overlaps are solved
// (contact_processing_threshold 0) and every overlap is split (the split
// impulse's threshold above any depth). Those solver settings cannot be made
// through the binding world.getSolverInfo(), which in this build returns a
// copy (solver_info below): they are written into the world's own.
//
// The world: one dynamic sphere and six static planes (btStaticPlaneShape,
// no margin, exact sphere-plane distance). The state is read from the
// engine's memory (the body's transform and velocity), not by binding calls.
//
// Every setting that changes the answer is an [engines.<name>] key with this
// adapter's value as its default (ownKeys below), so a test can put
// ammo.js's own default back; each goes into the run's settings with what
// the default did, measured.

import { createRequire } from 'node:module';
import {
  serve, ScenarioError, roomWalls, ContactStarts, ownKey, aNumber, nonNegative, count1, oneOf, trueOrFalse,
} from './host/protocol.mjs';

// ammo.js's own defaults (btContactSolverInfo.h, btRigidBodyConstructionInfo,
// btCollisionObject.cpp; read back from the module).
const AMMO = {
  wall_restitution: 0,
  wall_friction: 0.5,
  rolling_friction: 0,
  walls: null,               // ammo.js has no walls of its own (its examples build floors from boxes)
  contact_processing_threshold: 1e18,   // BT_LARGE_FLOAT
  contact_breaking_threshold: -1,       // -1: Bullet's own (0.02 x angular motion disc)
  split_impulse: true,
  split_impulse_penetration_threshold: -0.04,
  erp: 0.2,
  erp2: 0.8,
  iterations: 10,
  warm_starting: true,
  linear_damping: 0,
  angular_damping: 0,
  allow_sleep: true,
  stepping: 'fixed-1/60',
  ccd_motion_threshold: 0,
  solver_info: 'binding',
};

const ownKeys = {
  wall_restitution: 'the walls\' restitution; Bullet multiplies it with the ball\'s alpha (ammo.js: 0; here: 1)',
  wall_friction: 'the walls\' friction; Bullet multiplies it with the ball\'s mu (ammo.js: 0.5; here: 1)',
  rolling_friction: 'the ball\'s and walls\' rolling friction (ammo.js: 0)',
  walls: 'the walls\' shape: "planes" (btStaticPlaneShape, exact) or "boxes" (static btBoxShape, margin 0.04 within the box) (here: planes)',
  contact_processing_threshold: 'm (every body): a manifold point is solved only if its gap is at most this (ammo.js: BT_LARGE_FLOAT, 1e18; here: 0)',
  contact_breaking_threshold: 'm, written into every ball-wall manifold; -1 keeps Bullet\'s 0.02 x the sphere\'s angular motion disc (ammo.js: -1)',
  split_impulse: 'overlaps are pushed out by a position-only impulse (ammo.js: true)',
  split_impulse_penetration_threshold: 'm: split impulse only for overlaps deeper than -this (ammo.js: -0.04; here: 1e30, every overlap)',
  erp: 'Baumgarte factor: velocity added per metre of overlap and per step when split impulse is off (ammo.js: 0.2)',
  erp2: 'split impulse: fraction of an overlap pushed out per step (ammo.js: 0.8)',
  iterations: 'the solver\'s iterations per step (ammo.js: 10)',
  warm_starting: 'start a lasting contact from 0.85 x last step\'s impulse (ammo.js: true)',
  linear_damping: 'the ball\'s linear damping (ammo.js: 0)',
  angular_damping: 'the ball\'s angular damping (ammo.js: 0)',
  allow_sleep: 'the ball may fall asleep (ammo.js: true, 0.8 m/s and 1 rad/s for 2 s; here: false, DISABLE_DEACTIVATION)',
  stepping: '"single" stepSimulation(dt, 0): one internal step of dt; "fixed-dt" stepSimulation(dt, 1, dt); "fixed-1/60" stepSimulation(dt) (ammo.js\'s default arguments; here: single)',
  ccd_motion_threshold: 'm: CCD sweeps a step longer than this (swept sphere radius r); 0 off (ammo.js: 0)',
  solver_info: '"world": the solver settings are written into the world\'s own btContactSolverInfo; "binding": through world.getSolverInfo(), as ammo.js\'s API offers, which in 0.0.10 returns a copy, so they are lost (here: world)',
};

const STEPPINGS = ['single', 'fixed-dt', 'fixed-1/60'];
const DISABLE_DEACTIVATION = 4;

function fail(message) { throw new ScenarioError(message); }

// btContactSolverInfoData (btContactSolverInfo.h): float/int index of each field.
const SI = { numIterations: 5, erp: 8, erp2: 9, splitImpulse: 11, splitThreshold: 12, linearSlop: 14, warmFactor: 15, solverMode: 16 };
const SOLVER_USE_WARMSTARTING = 4;
// btDiscreteDynamicsWorld::m_solverInfo, bytes from the world's address (the
// compiled getSolverInfo binding copies from there).
const SOLVER_INFO_OFFSET = 92;

// The places in btRigidBody of the world transform's origin and of the linear
// velocity (float indices from the body's address), found once by probes.
let layout = null;
function findLayout(A, body) {
  const f = A.HEAPF32, p = body.ptr >> 2;
  const v = new A.btVector3(0.123456789, -0.234567891, 0.345678912);
  body.setLinearVelocity(v);
  const t = new A.btTransform();
  t.setIdentity();
  t.setOrigin(new A.btVector3(-0.456789123, 0.567891234, -0.678912345));
  body.setWorldTransform(t);
  const hit = (i, x) => f[p + i] === Math.fround(x[0]) && f[p + i + 1] === Math.fround(x[1]) && f[p + i + 2] === Math.fround(x[2]);
  let pos = -1, vel = -1;
  for (let i = 0; i < 256 && (pos < 0 || vel < 0); ++i) {
    if (pos < 0 && hit(i, [-0.456789123, 0.567891234, -0.678912345])) pos = i;
    if (vel < 0 && hit(i, [0.123456789, -0.234567891, 0.345678912])) vel = i;
  }
  A.destroy(v); A.destroy(t);
  if (pos < 0 || vel < 0) fail('ammo.js: the body\'s transform or velocity was not found in memory');
  return { pos, vel };
}

function build(A, s, settings) {
  const e = s.engine;
  const perContact = e.tangential_model === 'per-contact';
  const mu = perContact ? 0 : e.friction;
  const locked = e.rotation === 'locked';
  const dt = s.dt;

  const wallRestitution = ownKey(s, 'wall_restitution', 1.0, nonNegative);
  const wallFriction = ownKey(s, 'wall_friction', 1.0, nonNegative);
  const rollingFriction = ownKey(s, 'rolling_friction', AMMO.rolling_friction, nonNegative);
  const wallShape = ownKey(s, 'walls', 'planes', oneOf('planes', 'boxes'));
  const processing = ownKey(s, 'contact_processing_threshold', 0.0, aNumber);
  const breaking = ownKey(s, 'contact_breaking_threshold', AMMO.contact_breaking_threshold, aNumber);
  const splitImpulse = ownKey(s, 'split_impulse', AMMO.split_impulse, trueOrFalse);
  const splitThreshold = ownKey(s, 'split_impulse_penetration_threshold', 1e30, aNumber);
  const erp = ownKey(s, 'erp', AMMO.erp, nonNegative);
  const erp2 = ownKey(s, 'erp2', AMMO.erp2, nonNegative);
  const iterations = ownKey(s, 'iterations', AMMO.iterations, count1);
  const warmStarting = ownKey(s, 'warm_starting', AMMO.warm_starting, trueOrFalse);
  const linearDamping = ownKey(s, 'linear_damping', AMMO.linear_damping, nonNegative);
  const angularDamping = ownKey(s, 'angular_damping', AMMO.angular_damping, nonNegative);
  const allowSleep = ownKey(s, 'allow_sleep', false, trueOrFalse);
  const stepping = ownKey(s, 'stepping', 'single', oneOf(...STEPPINGS));
  const ccdDefault = e.ccd === true ? 1e-7 : AMMO.ccd_motion_threshold;
  const ccdThreshold = ownKey(s, 'ccd_motion_threshold', ccdDefault, nonNegative);
  const solverInfo = ownKey(s, 'solver_info', 'world', oneOf('world', 'binding'));

  const owned = [];
  const keep = (o) => { owned.push(o); return o; };
  const vec = (x, y, z) => keep(new A.btVector3(x, y, z));

  // ---- The world ----
  const config = keep(new A.btDefaultCollisionConfiguration());
  const dispatcher = keep(new A.btCollisionDispatcher(config));
  const broadphase = keep(new A.btDbvtBroadphase());
  const solver = keep(new A.btSequentialImpulseConstraintSolver());
  const world = new A.btDiscreteDynamicsWorld(dispatcher, broadphase, solver, config);
  world.setGravity(vec(s.gravity[0], s.gravity[1], s.gravity[2]));  // before the ball is added: addRigidBody copies it

  // The solver's settings are written into the world's own
  // btContactSolverInfoData, in memory (layout checked by its defaults). The
  // binding world.getSolverInfo() cannot be used: ammo.js 0.0.10 declares it
  // `[Value] btContactSolverInfo getSolverInfo();` (ammo.idl, commit 5881fcc),
  // so it returns a copy in a static buffer (the compiled binding copies 84
  // bytes from the world + 92 to a fixed address on every call) and whatever
  // is set on it is lost; upstream made it [Ref] in 2017 (commit 925e97b).
  // The world's m_solverInfo is that source, world + 92 bytes.
  // solver_info = "binding" writes where the binding points instead (its copy),
  // to show what a user of the API gets.
  const F = A.HEAPF32, I = A.HEAP32, si = (world.ptr + SOLVER_INFO_OFFSET) >> 2;
  const copy = world.getSolverInfo().ptr;
  const target = solverInfo === 'world' || copy === world.ptr + SOLVER_INFO_OFFSET ? si : copy >> 2;
  if (F[si + SI.erp] !== Math.fround(0.2) || F[si + SI.erp2] !== Math.fround(0.8) || I[si + SI.numIterations] !== 10
      || F[si + SI.splitThreshold] !== Math.fround(-0.04) || I[si + SI.solverMode] !== 260)
    fail('ammo.js: btContactSolverInfo is not laid out as Bullet 2.82\'s');
  I[target + SI.numIterations] = iterations;
  F[target + SI.erp] = erp;
  F[target + SI.erp2] = erp2;
  I[target + SI.splitImpulse] = splitImpulse ? 1 : 0;
  F[target + SI.splitThreshold] = Math.min(splitThreshold, 3e38);
  I[target + SI.solverMode] = 256 | (warmStarting ? SOLVER_USE_WARMSTARTING : 0);
  world.getDispatchInfo().set_m_allowedCcdPenetration(0);

  // ---- The walls ----
  const walls = roomWalls(s);
  const thickness = Math.max(...s.room);
  const wallBodies = [];
  const zero = vec(0, 0, 0);
  for (const w of walls) {
    const t = keep(new A.btTransform());
    t.setIdentity();
    let shape;
    if (wallShape === 'planes') {
      const n = [0, 0, 0];
      n[w.axis] = -w.side;  // the inward normal
      // n . x = constant: the lower wall 0, the upper -room (n = -1)
      shape = keep(new A.btStaticPlaneShape(vec(n[0], n[1], n[2]), w.side < 0 ? 0 : -s.room[w.axis]));
    } else {
      const centre = s.room.map((l) => l / 2);
      centre[w.axis] = w.side < 0 ? -thickness / 2 : s.room[w.axis] + thickness / 2;
      const half = s.room.map((l) => l / 2 + thickness);
      half[w.axis] = thickness / 2;
      shape = keep(new A.btBoxShape(vec(half[0], half[1], half[2])));
      t.setOrigin(vec(centre[0], centre[1], centre[2]));
    }
    const ci = keep(new A.btRigidBodyConstructionInfo(0, keep(new A.btDefaultMotionState(t)), shape, zero));
    ci.set_m_restitution(wallRestitution);
    ci.set_m_friction(wallFriction);
    ci.set_m_rollingFriction(rollingFriction);
    const body = keep(new A.btRigidBody(ci));
    body.setContactProcessingThreshold(processing);
    world.addRigidBody(body);
    wallBodies.push(body);
  }

  // ---- The ball ----
  const sphere = keep(new A.btSphereShape(s.radius));
  const mass = 1;
  const inertia = vec(0, 0, 0);
  sphere.calculateLocalInertia(mass, inertia);
  const start = keep(new A.btTransform());
  start.setIdentity();
  start.setOrigin(vec(s.position[0], s.position[1], s.position[2]));
  const ci = keep(new A.btRigidBodyConstructionInfo(mass, keep(new A.btDefaultMotionState(start)), sphere, inertia));
  ci.set_m_restitution(s.alpha);
  ci.set_m_friction(mu);
  ci.set_m_rollingFriction(rollingFriction);
  ci.set_m_linearDamping(linearDamping);
  ci.set_m_angularDamping(angularDamping);
  const ball = keep(new A.btRigidBody(ci));
  ball.setContactProcessingThreshold(processing);
  if (locked) ball.setAngularFactor(vec(0, 0, 0));
  if (ccdThreshold > 0) { ball.setCcdMotionThreshold(ccdThreshold); ball.setCcdSweptSphereRadius(s.radius); }
  world.addRigidBody(ball);
  if (!allowSleep) ball.setActivationState(DISABLE_DEACTIVATION);
  if (!layout) layout = findLayout(A, ball);
  ball.setWorldTransform(start);
  const motion = ball.getMotionState();
  motion.setWorldTransform(start);
  ball.setLinearVelocity(vec(s.velocity[0], s.velocity[1], s.velocity[2]));
  ball.setAngularVelocity(vec(0, 0, 0));
  const posAt = (ball.ptr >> 2) + layout.pos, velAt = (ball.ptr >> 2) + layout.vel;
  if (F[posAt] !== Math.fround(s.position[0]) || F[velAt] !== Math.fround(s.velocity[0])) fail('ammo.js: the ball\'s state is not where the probe found it');

  // ---- Contacts, from the dispatcher's manifolds after the step ----
  const wallPtrs = wallBodies.map((b) => b.ptr);
  const touching = new Array(walls.length).fill(false);
  function readContacts() {
    touching.fill(false);
    const n = dispatcher.getNumManifolds();
    for (let i = 0; i < n; ++i) {
      const m = dispatcher.getManifoldByIndexInternal(i);
      // Bullet pools its manifolds: one freed and reused keeps no threshold
      // of ours, so the value is checked in memory at every step.
      if (breaking >= 0 && (manifoldBodies < 0 || A.HEAPF32[(m.ptr >> 2) + manifoldBodies + 3] !== Math.fround(breaking)))
        setBreaking(m, breaking);
      const k = m.getNumContacts();
      if (k === 0) continue;
      const b0 = m.getBody0().ptr, b1 = m.getBody1().ptr;
      const w = wallPtrs.indexOf(b0 === ball.ptr ? b1 : b0);
      if (w < 0) continue;
      for (let j = 0; j < k; ++j) if (m.getContactPoint(j).getDistance() <= processing) { touching[w] = true; break; }
    }
  }

  let afterStep = null;
  const before = new Float64Array(3);
  if (perContact) {
    // No contact-added callback in this build (ammo.idl binds none): a wall
    // whose manifold holds a point the solver took (gap <= the processing
    // threshold) after the step, and not after the one before, starts a
    // contact if the ball moved into it before the step (ContactStarts);
    // Bullet bounced it in this same step, and the velocity is scaled off the
    // starting walls' normals by beta, once.
    const starts = new ContactStarts(s);
    afterStep = () => {
      readContacts();
      const axes = starts.starting(touching, before);
      if (axes.length > 0) {
        const f = A.HEAPF32;
        const v = starts.scaled([f[velAt], f[velAt + 1], f[velAt + 2]], axes);
        f[velAt] = v[0]; f[velAt + 1] = v[1]; f[velAt + 2] = v[2];
      }
    };
  } else if (breaking >= 0) {
    afterStep = readContacts;
  }

  // ---- Settings ----
  const add = (key, value, why) => settings.add(key, value, why);
  const mark = (value, key) => (value === AMMO[key] ? ' [ammo.js\'s default]' : '');
  add('tangential_model', perContact ? `per-contact: beta = ${s.beta} once at each contact's start, after the step` : `friction: Coulomb mu = ${mu}`,
    perContact ? 'ammo.js binds no contact-added callback; the manifolds after the step show which walls the solver took this step (protocol ContactStarts)' : 'the scenario\'s [engines.<name>] friction');
  // Measured on seed-3d, per-contact, dt 1e-3 unless noted (REPORT: docs/engines.md, ammo.js).
  add('restitution', `ball ${s.alpha}, walls ${wallRestitution}, product (btManifoldResult::calculateCombinedRestitution)`,
    'walls 1 give alpha; ammo.js\'s 0 gives 0: the ball lands at 5.65 s and stays (highest 6-11 s 0.0500 m against 0.4590)' + mark(wallRestitution, 'wall_restitution'));
  add('friction', `ball ${mu}, walls ${wallFriction}, product (btManifoldResult::calculateCombinedFriction)`,
    'walls 1 give mu; ammo.js\'s 0.5 gives mu / 2 (friction mode, mu 0.00553855: highest 6-11 s 0.4655 m against 0.4625)' + mark(wallFriction, 'wall_friction'));
  add('rolling_friction', rollingFriction, 'none in the law' + mark(rollingFriction, 'rolling_friction'));
  add('walls', wallShape === 'planes' ? 'six btStaticPlaneShape, exact' : `six static boxes ${thickness} m thick, margin 0.04 m within`,
    'planes: exact sphere-plane distance; boxes (margin inside the box, faces on the walls) give the same figures to 0.001% (deepest 0.270 against 0.273 mm)');
  add('contact_processing_threshold', processing,
    'a solved point with gap d > 0 is asked for alpha u - d / dt (btSequentialImpulseConstraintSolver.cpp:666, 704, 713-717): ammo.js\'s 1e18 solves every point within the 1.73 mm breaking gap, so the bounce loses up to 1.73 m/s at dt 1e-3; the seed ball lands and stays (highest 6-11 s 0.0500 m); effective alpha 0.50-0.80 (worst 0.23) on the bar scenarios. 0: only overlaps are solved, alpha u exactly' + mark(processing, 'contact_processing_threshold'));
  add('contact_breaking_threshold', breaking >= 0 ? breaking : 'Bullet\'s (0.02 x angular motion disc: 1.73 mm at r 5 cm)',
    'with processing 0 it only decides how long a point is kept. The compiled bullet adapter\'s 1e-9 m (with processing left at 1e18) loses contacts in f32: refreshContactPoints drops a point whose drift exceeds it, and f32 round-off alone is 1e-8 m: seed-3d\'s ball leaves the room at 1.684 s' + mark(breaking, 'contact_breaking_threshold'));
  add('split_impulse', `${splitImpulse ? 'on' : 'off'}, penetration threshold ${splitThreshold}, erp2 ${erp2}`,
    'an overlap p shallower than -threshold is not split: the bounce gets erp p / dt on top (lines 707-737). ammo.js\'s -0.04 m: alpha 0.80-0.97 per impact, highest 6-11 s 0.6230 m against 0.4590 (split_impulse off: the same rows). erp2 1 instead of 0.8: alpha +0.001' + mark(splitThreshold, 'split_impulse_penetration_threshold'));
  add('solver_info', target === si ? 'written into the world\'s m_solverInfo (world + 92 bytes)' : 'written through world.getSolverInfo(): a copy, lost',
    'ammo.js 0.0.10\'s getSolverInfo() returns a copy ([Value] in ammo.idl): the solver settings set through it do nothing, as if all were ammo.js\'s (highest 6-11 s 0.6230 m against 0.4590)' + mark(solverInfo, 'solver_info'));
  add('erp', erp, 'Baumgarte, only for an overlap that is not split' + mark(erp, 'erp'));
  add('iterations', iterations, 'one ball, at most three walls: 1 iteration gives the bar scenarios bit for bit' + mark(iterations, 'iterations'));
  add('warm_starting', warmStarting, 'a lasting contact starts from 0.85 x its last impulse; off gives the bar scenarios bit for bit' + mark(warmStarting, 'warm_starting'));
  add('damping', `linear ${linearDamping}, angular ${angularDamping}`, 'ammo.js\'s are 0');
  add('sleeping', allowSleep ? 'ammo.js\'s (0.8 m/s, 1 rad/s for 2 s)' : 'off (DISABLE_DEACTIVATION)',
    'ammo.js\'s default freezes the seed-3d ball at its first apex (z 0.6995 m from 2 s, never lands) and stops a ball sliding at 0.02 m/s');
  add('stepping', stepping === 'single' ? `stepSimulation(${dt}, 0): one internal step of dt` : stepping === 'fixed-dt' ? `stepSimulation(${dt}, 1, ${dt})` : `stepSimulation(${dt}) (maxSubSteps 1, fixedTimeStep 1/60)`,
    'maxSubSteps 0 is the variable-step mode: exactly one step of dt (btDiscreteDynamicsWorld.cpp:415-430); (dt, 1, dt) gave the same rows; the default arguments step 1/60 s at most once a call: at dt 0.03 the first floor contact comes at 10.17 s instead of 5.64' + mark(stepping, 'stepping'));
  add('ccd', ccdThreshold > 0 ? `motion threshold ${ccdThreshold} m, swept sphere r, allowed penetration 0` : 'off',
    'Bullet 2.82\'s predictive CCD contact carries restitution 0 (btDiscreteDynamicsWorld.cpp:959): with a threshold of 1e-7 m no ball bounces (measured alpha 0 on the bar scenarios)' + mark(ccdThreshold, 'ccd_motion_threshold'));
  add('rotation', locked ? 'locked (angular factor 0)' : 'free', 'scenario [engines.<name>] rotation');
  add('gravity', `(${s.gravity.join(', ')}) m/s^2`, 'the scenario\'s, set before the ball is added (ammo.js: (0, -10, 0))');

  const v0 = before;
  return {
    step() {
      if (afterStep) { const f = A.HEAPF32; v0[0] = f[velAt]; v0[1] = f[velAt + 1]; v0[2] = f[velAt + 2]; }
      if (stepping === 'single') world.stepSimulation(dt, 0);
      else if (stepping === 'fixed-dt') world.stepSimulation(dt, 1, dt);
      else world.stepSimulation(dt);
      if (afterStep) afterStep();
    },
    read(out) {
      const f = A.HEAPF32;
      out[0] = f[posAt]; out[1] = f[posAt + 1]; out[2] = f[posAt + 2];
      out[3] = f[velAt]; out[4] = f[velAt + 1]; out[5] = f[velAt + 2];
    },
    free() {
      world.removeRigidBody(ball);
      for (const b of wallBodies) world.removeRigidBody(b);
      A.destroy(world);
      for (const o of owned.reverse()) A.destroy(o);
    },
  };

  // btPersistentManifold::m_contactBreakingThreshold, written in memory (no
  // binding): it follows m_body0, m_body1 and m_cachedPoints
  // (btPersistentManifold.h), and m_contactProcessingThreshold follows it.
  function setBreaking(m, value) {
    const i = A.HEAP32, f = A.HEAPF32, p = m.ptr >> 2;
    const b0 = m.getBody0().ptr, b1 = m.getBody1().ptr;
    if (manifoldBodies < 0) {
      for (let k = 0; k < 1024; ++k) if (i[p + k] === b0 && i[p + k + 1] === b1) { manifoldBodies = k; break; }
      if (manifoldBodies < 0) fail('ammo.js: btPersistentManifold\'s bodies were not found in memory');
    }
    if (i[p + manifoldBodies] !== b0 || f[p + manifoldBodies + 4] !== Math.fround(processing)) fail('ammo.js: btPersistentManifold is not laid out as expected');
    f[p + manifoldBodies + 3] = value;
  }
}

// The int index of m_body0 in btPersistentManifold, found once.
let manifoldBodies = -1;

export const adapter = {
  name: 'ammo',
  dimensions: [3],
  precision: 'f32',
  packages: () => ['ammo.js'],
  ownKeys,
  // ammo.js 0.0.10 is a UMD file whose CommonJS branch exports the module
  // itself, already instantiated (it calls Ammo() before returning).
  async load() { return createRequire(import.meta.url)('ammo.js'); },
  version: () => 'Bullet 2.82 (BT_BULLET_VERSION 282), asm.js',
  build,
};

await serve(adapter);
