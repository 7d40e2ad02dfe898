// NVIDIA PhysX 5 (npm physx-js-webidl, an Emscripten build; f32) as a
// bouncecheck engine: `node physx.mjs` speaks bouncecheck-external/1
// (docs/external.md) through host/protocol.mjs. 3D only.
//
// The world: a dynamic sphere (1 kg, inertia 2/5 m r^2) and the room as six
// static planes (half-spaces: however deep the ball gets it still has a
// contact), each with its own material carrying alpha and mu, so every
// combine mode but multiply gives alpha and mu. Each engine step is
// inner_steps x (scene.simulate(dt / n) + fetchResults(true)), on the calling
// thread (a CPU dispatcher with no workers).
//
// How PhysX bounces (PGS, DyContactPrepShared.h, constructContactConstraint,
// PhysX 5.6.1): a contact point exists from a separation below the two
// shapes' contact offsets; restitution applies when the normal velocity is
// above the bounce threshold and the ball would reach the wall within the
// step (separation + dt v_n < 0): the solver then sets the normal velocity to
// alpha times the approach speed, with no position bias if the separation
// is within ccdMaxSeparation. So the ball turns in the step before it would
// cross the wall (it never sinks in), provided the contact offset covers a
// step's travel.
//
// Loading under Node: physx-js-webidl is built for the web only
// (-sENVIRONMENT=web). Its opening minimum_runtime_check throws whenever
// process.versions.node is set, before it reads a single Module option, and
// its environment detection then needs globalThis.window; no option
// (wasmBinary, locateFile, instantiateWasm) gets past that. load() hides
// process.versions.node and shows a `window` only for the synchronous start
// of the factory (where both checks run), restores both before anything else
// runs, and hands the .wasm bytes over as wasmBinary, so the build's fetch()
// is never used. See loadPhysX().
//
// Per-contact mode: PhysX's own contact reports. The ball's filter data asks
// the default filter shader (PxDefaultSimulationFilterShader ORs
// filterData.word2 into the pair flags) for eNOTIFY_TOUCH_FOUND / _LOST and
// eNOTIFY_THRESHOLD_FORCE_FOUND (the ball's contact report threshold is 0),
// and a PxSimulationEventCallback (JS) marks a wall when a touch first pushes:
// the step that turns the ball (a touch alone starts up to the contact
// distance before the wall). onContact runs inside fetchResults, after the
// solver, and the WebIDL binding has no PxContactModifyCallback: beta goes on
// the velocity after that step, through the protocol's ContactStarts, judged
// on the velocity the step started from.
import fs from 'node:fs';
import { createRequire } from 'node:module';
import { serve, ScenarioError, roomWalls, maxBallSpeed, ContactStarts,
  ownKey, positive, nonNegative, count1, anIntegerIn, oneOf, either, listOf } from './host/protocol.mjs';

const require = createRequire(import.meta.url);

const ownKeys = {
  bounce_threshold: 'm/s: a contact slower than this does not bounce; chosen 1e-6 (it must be > 0), PhysX default 2.0 (0.2 x tolerances speed 10)',
  solver: '"PGS" (chosen, PhysX default) or "TGS"',
  restitution_combine: '"average" (chosen, PhysX default), "min", "max" or "multiply" (ball and walls both carry alpha)',
  friction_combine: '"average" (chosen, PhysX default), "min", "max" or "multiply" (ball and walls both carry mu)',
  contact_offset: '"auto" (chosen: each shape half of max(r / 10, the largest step travel - 0.8 max(2 mm, 2% r))) or metres per shape; PhysX default 0.02 (x tolerances length 1)',
  rest_offset: 'metres per shape; chosen 0 (PhysX default)',
  ccd_max_separation: '"auto" (chosen: the contact distance, twice the largest step travel with ccd, at least 0.04) or metres; PhysX default 0.04',
  sleep_threshold: 'mass-normalised kinetic energy (m^2/s^2) below which the ball may sleep; chosen 0 (never), PhysX default 0.005 (5e-5 x speed^2)',
  linear_damping: 'chosen 0 (PhysX default for a dynamic body)',
  angular_damping: 'chosen 0, PhysX default 0.05',
  max_angular_velocity: 'rad/s; chosen 1e7, PhysX default 100',
  iterations: '[position, velocity] solver iterations; chosen [4, 1] (PhysX default)',
  inner_steps: '"auto" (chosen: simulate calls of dt / n per engine step, n from the floor bounce\'s gain, see innerSteps) or an integer >= 1 (1: one simulate(dt) per step)',
};

const COMBINE = { average: 'eAVERAGE', min: 'eMIN', max: 'eMAX', multiply: 'eMULTIPLY' };

const COMBINE_RULE = oneOf(...Object.keys(COMBINE));
const AUTO = oneOf('auto');

function tuning(s) {
  return {
    bounce_threshold: ownKey(s, 'bounce_threshold', 1e-6, positive),
    solver: ownKey(s, 'solver', 'PGS', oneOf('PGS', 'TGS')),
    restitution_combine: ownKey(s, 'restitution_combine', 'average', COMBINE_RULE),
    friction_combine: ownKey(s, 'friction_combine', 'average', COMBINE_RULE),
    contact_offset: ownKey(s, 'contact_offset', 'auto', either(AUTO, positive)),
    rest_offset: ownKey(s, 'rest_offset', 0, nonNegative),
    ccd_max_separation: ownKey(s, 'ccd_max_separation', 'auto', either(AUTO, nonNegative)),
    sleep_threshold: ownKey(s, 'sleep_threshold', 0, nonNegative),
    linear_damping: ownKey(s, 'linear_damping', 0, nonNegative),
    angular_damping: ownKey(s, 'angular_damping', 0, nonNegative),
    max_angular_velocity: ownKey(s, 'max_angular_velocity', 1e7, positive),
    inner_steps: ownKey(s, 'inner_steps', 'auto', either(AUTO, count1)),
    iterations: ownKey(s, 'iterations', [4, 1], listOf(2, anIntegerIn(1, 255), '[position, velocity], integers 1..255')),
  };
}

// ---- Loading the web-only build under Node ----

async function loadPhysX() {
  const { default: PhysX } = await import('physx-js-webidl');
  const wasmBinary = fs.readFileSync(require.resolve('physx-js-webidl/physx-js-webidl.wasm'));
  const toStderr = (text) => process.stderr.write(`physx-js-webidl: ${text}\n`);
  const versions = Object.getOwnPropertyDescriptor(process, 'versions');
  const window = Object.getOwnPropertyDescriptor(globalThis, 'window');
  let pending;
  try {
    // Both checks run in the factory's synchronous start (before its first
    // await): minimum_runtime_check reads process.versions.node, the
    // environment detection globalThis.window.
    Object.defineProperty(process, 'versions', { ...versions, value: { ...versions.value, node: undefined } });
    Object.defineProperty(globalThis, 'window', { value: globalThis, configurable: true, writable: true });
    // print / printErr: the build's `out` is console.log, i.e. the trajectory's stream.
    pending = PhysX({ wasmBinary, print: toStderr, printErr: toStderr });
  } finally {
    Object.defineProperty(process, 'versions', versions);
    if (window) Object.defineProperty(globalThis, 'window', window); else delete globalThis.window;
  }
  const px = await pending;
  // The SDK objects PhysX allows once per process.
  const T = px.PxTopLevelFunctions.prototype;
  const version = T.PHYSICS_VERSION;
  const errors = { sink: null };
  const errorCallback = new px.PxErrorCallbackImpl();
  const decoder = new TextDecoder();
  const cString = (ptr) => {
    const heap = px.HEAPU8;
    let end = ptr;
    while (heap[end]) ++end;
    return decoder.decode(heap.subarray(ptr, end));
  };
  errorCallback.reportError = (code, message, file, line) => {
    const text = `PhysX error ${code}: ${cString(message)} (${cString(file)}:${line})`;
    if (code === px.PxErrorCodeEnum.eDEBUG_INFO || code === px.PxErrorCodeEnum.eDEBUG_WARNING || code === px.PxErrorCodeEnum.ePERF_WARNING) {
      process.stderr.write(`${text}\n`);
    } else if (errors.sink) errors.sink.push(text);
    else process.stderr.write(`${text}\n`);
  };
  const foundation = T.CreateFoundation(version, new px.PxDefaultAllocator(), errorCallback);
  const scale = new px.PxTolerancesScale();  // length 1, speed 10: PhysX's defaults
  const physics = T.CreatePhysics(version, foundation, scale);
  const dispatcher = T.DefaultCpuDispatcherCreate(0);
  return { px, T, version, physics, scale, dispatcher, errors };
}

let library = null;

// How many simulate() calls make one engine step. PGS's restitution target
// is alpha times the approach speed *after* this step's gravity, and the
// solver fixes the velocity the step ends with: a floor bounce leaves at
// alpha (u + |g| h) from above the floor where the law's ball has lost
// (1 - tau / h) |g| h since the contact, a gain of about
// (1 + alpha) |g| h / (alpha u) in outgoing speed per floor bounce (measured
// to 1e-3 on earth-drop's first bounce), twice that in height, and growing
// as the bounces slow (u -> alpha u). auto: n so that the gains summed over
// the first three floor bounces, (1 + alpha) |g| h / u1 (1 + 1/alpha +
// 1/alpha^2) with u1 the first impact speed, stay within 1% (measured at
// h = 1e-3: predicted 1.68% / 4.06%, measured third-apex errors 1.83% / 4.72%
// on earth-drop / a 1 cm ball in a 0.2 m room).
function innerSteps(s, t) {
  const d = s.dimension;
  let axis = d - 1;  // the axis gravity pulls along most: the vertical, normally
  for (let i = 0; i < d; ++i) if (Math.abs(s.gravity[i]) > Math.abs(s.gravity[axis])) axis = i;
  const g = Math.abs(s.gravity[axis]);
  const fall = s.gravity[axis] < 0 ? s.position[axis] - s.radius : s.room[axis] - s.radius - s.position[axis];
  const u1 = Math.sqrt(s.velocity[axis] ** 2 + 2 * g * Math.max(0, fall));
  const a = Math.max(s.alpha, 0.1);
  const predicted = u1 > 0 && g > 0 ? (1 + a) * g * s.dt / u1 * (1 + 1 / a + 1 / (a * a)) : 0;
  const auto = Math.max(1, Math.ceil(predicted / 0.01 - 1e-9));
  return { n: t.inner_steps === 'auto' ? auto : t.inner_steps, auto, predicted, u1 };
}

// Plane geometry is the plane x = 0 with normal +x: the rotation that turns
// +x into the wall's inward normal, as a quaternion (x, y, z, w).
const H = Math.SQRT1_2;
const PLANE_ROTATION = {
  '0,-1': [0, 0, 0, 1], '0,1': [0, 0, 1, 0],     // normal +x, -x
  '1,-1': [0, 0, H, H], '1,1': [0, 0, -H, H],     // +y, -y
  '2,-1': [0, -H, 0, H], '2,1': [0, H, 0, H],     // +z, -z
};

const adapter = {
  name: 'physx',
  dimensions: [3],
  precision: 'f32',
  packages: () => ['physx-js-webidl'],
  ownKeys,
  async load() {
    if (!library) library = loadPhysX();
    return library;
  },
  version: (lib) => {
    const v = lib.version;
    return `PhysX ${v >>> 24}.${(v >>> 16) & 255}.${(v >>> 8) & 255}`;
  },
  build(lib, s, settings) {
    const { px, T, physics, dispatcher } = lib;
    const t = tuning(s);
    const perContact = s.engine.tangential_model === 'per-contact';
    const mu = perContact ? 0 : s.engine.friction;  // the shared keys are checked by host/protocol.mjs
    const ccd = s.engine.ccd === true;
    const errors = [];
    lib.errors.sink = errors;
    const check = (what) => {
      if (errors.length) throw new ScenarioError(`${what}: ${errors.join('; ')}`);
    };

    // The contact distance (the two shapes' offsets) decides where the ball
    // turns: PhysX turns it in the step that would carry it into the wall if
    // a contact point exists at that step's start (separation below the
    // distance), up to the distance before the wall; else in the next step,
    // up to a step's travel inside. auto: a tenth of the radius, more if a
    // step's travel at the energy bound's speed would otherwise sink the ball
    // beyond 0.8 of the skin max(2 mm, 2% r).
    const inner = innerSteps(s, t);
    const h = s.dt / inner.n;
    const travel = maxBallSpeed(s) * h;
    const skin = Math.max(0.002, 0.02 * s.radius);
    const contactOffset = t.contact_offset === 'auto' ? Math.max(0.1 * s.radius, travel - 0.8 * skin) / 2 : t.contact_offset;
    if (contactOffset <= t.rest_offset) throw new ScenarioError('contact_offset must be larger than rest_offset');
    const ccdMaxSeparation = t.ccd_max_separation === 'auto' ? Math.max(0.04, 2 * contactOffset, ccd ? 2 * travel : 0) : t.ccd_max_separation;

    const keep = [];  // WebIDL objects made here, destroyed in free()
    const make = (o) => { keep.push(o); return o; };
    const vec = (x, y, z) => make(new px.PxVec3(x, y, z));

    // ---- Scene ----
    const desc = make(new px.PxSceneDesc(lib.scale));
    desc.gravity = vec(s.gravity[0], s.gravity[1], s.gravity[2]);
    desc.cpuDispatcher = dispatcher;
    desc.filterShader = T.DefaultFilterShader();
    desc.solverType = t.solver === 'PGS' ? px.PxSolverTypeEnum.ePGS : px.PxSolverTypeEnum.eTGS;
    desc.bounceThresholdVelocity = t.bounce_threshold;
    desc.ccdMaxSeparation = ccdMaxSeparation;

    // Contact reports (per-contact mode). A touch (eNOTIFY_TOUCH_FOUND .. _LOST)
    // begins once the separation is below the contact distance, which can be
    // steps before the ball reaches the wall; the contact the law counts
    // starts at the first step of the touch in which the wall pushes
    // (eNOTIFY_THRESHOLD_FORCE_FOUND with a force threshold of 0): the step
    // that turns the ball. `pushed[w]`: the touch with wall w has pushed.
    const walls = roomWalls(s);
    const touching = new Array(walls.length).fill(false);
    const pushed = new Array(walls.length).fill(false);
    const wallOfActor = new Map();
    let events = 0;
    let callback = null;
    const FOUND = px.PxPairFlagEnum.eNOTIFY_TOUCH_FOUND, LOST = px.PxPairFlagEnum.eNOTIFY_TOUCH_LOST;
    const FORCE = px.PxPairFlagEnum.eNOTIFY_THRESHOLD_FORCE_FOUND;
    if (perContact) {
      callback = make(new px.PxSimulationEventCallbackImpl());
      callback.onContact = (headerPtr, pairsPtr, nbPairs) => {
        const header = px.wrapPointer(headerPtr, px.PxContactPairHeader);
        const a0 = header.get_actors(0).ptr, a1 = header.get_actors(1).ptr;
        const w = wallOfActor.has(a0) ? wallOfActor.get(a0) : wallOfActor.get(a1);
        if (w === undefined) return;
        const first = px.wrapPointer(pairsPtr, px.PxContactPair);
        for (let i = 0; i < nbPairs; ++i) {
          const pair = i === 0 ? first : px.NativeArrayHelpers.prototype.getContactPairAt(first, i);
          const flags = pair.get_events();
          if (flags.isSet(FOUND)) touching[w] = true;
          if (flags.isSet(FORCE) && touching[w]) pushed[w] = true;
          if (flags.isSet(LOST)) touching[w] = pushed[w] = false;
          ++events;
        }
      };
      callback.onConstraintBreak = () => {};
      callback.onWake = () => {};
      callback.onSleep = () => {};
      callback.onTrigger = () => {};
      desc.simulationEventCallback = callback;
    }
    const scene = physics.createScene(desc);
    check('PxPhysics::createScene');
    if (!scene) throw new ScenarioError('PhysX could not create the scene');

    // ---- Materials: ball and walls both carry alpha and mu ----
    const material = () => {
      const m = physics.createMaterial(mu, mu, s.alpha);
      m.setRestitutionCombineMode(px.PxCombineModeEnum[COMBINE[t.restitution_combine]]);
      m.setFrictionCombineMode(px.PxCombineModeEnum[COMBINE[t.friction_combine]]);
      return m;
    };
    const wallMaterial = material(), ballMaterial = material();

    const notify = perContact ? FOUND | LOST | FORCE : 0;
    const filter = (word2) => make(new px.PxFilterData(1, 1, word2, 0));
    const shapeFlags = make(new px.PxShapeFlags(px.PxShapeFlagEnum.eSIMULATION_SHAPE));

    // ---- Walls ----
    const statics = [];
    const planeGeometry = make(new px.PxPlaneGeometry());
    walls.forEach((w, i) => {
      const p = [0, 0, 0];
      p[w.axis] = w.offset;
      const q = PLANE_ROTATION[`${w.axis},${w.side}`];
      const pose = make(new px.PxTransform(vec(p[0], p[1], p[2]), make(new px.PxQuat(q[0], q[1], q[2], q[3]))));
      const actor = physics.createRigidStatic(pose);
      const shape = physics.createShape(planeGeometry, wallMaterial, true, shapeFlags);
      shape.setContactOffset(contactOffset);
      shape.setRestOffset(t.rest_offset);
      shape.setSimulationFilterData(filter(0));
      actor.attachShape(shape);
      shape.release();  // the actor holds it
      scene.addActor(actor);
      wallOfActor.set(actor.ptr, i);
      statics.push(actor);
    });

    // ---- Ball ----
    const identity = make(new px.PxQuat(0, 0, 0, 1));
    const body = physics.createRigidDynamic(make(new px.PxTransform(vec(s.position[0], s.position[1], s.position[2]), identity)));
    const sphere = make(new px.PxSphereGeometry(s.radius));
    const ballShape = physics.createShape(sphere, ballMaterial, true, shapeFlags);
    ballShape.setContactOffset(contactOffset);
    ballShape.setRestOffset(t.rest_offset);
    ballShape.setSimulationFilterData(filter(notify));
    body.attachShape(ballShape);
    ballShape.release();
    body.setMass(1);
    const inertia = 0.4 * s.radius * s.radius;
    body.setMassSpaceInertiaTensor(vec(inertia, inertia, inertia));
    body.setLinearDamping(t.linear_damping);
    body.setAngularDamping(t.angular_damping);
    body.setMaxAngularVelocity(t.max_angular_velocity);
    body.setSleepThreshold(t.sleep_threshold);
    body.setSolverIterationCounts(t.iterations[0], t.iterations[1]);
    // ccd = true: PhysX's speculative CCD (the contact distance grows with the
    // step's motion). Its sweep CCD (eENABLE_CCD) never acts against a plane:
    // computeCCDThreshold gives a plane PX_MAX_REAL (PxsCCD.cpp).
    if (ccd) body.setRigidBodyFlag(px.PxRigidBodyFlagEnum.eENABLE_SPECULATIVE_CCD, true);
    if (perContact) body.setContactReportThreshold(0);  // any push raises eNOTIFY_THRESHOLD_FORCE_FOUND
    if (s.engine.rotation === 'locked') {
      body.setRigidDynamicLockFlag(px.PxRigidDynamicLockFlagEnum.eLOCK_ANGULAR_X, true);
      body.setRigidDynamicLockFlag(px.PxRigidDynamicLockFlagEnum.eLOCK_ANGULAR_Y, true);
      body.setRigidDynamicLockFlag(px.PxRigidDynamicLockFlagEnum.eLOCK_ANGULAR_Z, true);
    }
    const velocity = vec(s.velocity[0], s.velocity[1], s.velocity[2]);
    body.setLinearVelocity(velocity, true);
    scene.addActor(body);
    check('building the world');

    report(px, s, t, { mu, contactOffset, ccdMaxSeparation, travel, perContact, ccd, inner, settings });

    // ---- Stepping and reading ----
    // getGlobalPose and getLinearVelocity return pointers to static
    // temporaries of the binding; their floats are read straight from the
    // WebAssembly memory: two calls per read, no wrapper objects.
    const getPose = px._emscripten_bind_PxRigidDynamic_getGlobalPose_0;
    const getVelocity = px._emscripten_bind_PxRigidDynamic_getLinearVelocity_0;
    const bodyPtr = body.ptr;
    let f32 = new Float32Array(px.HEAPU8.buffer);
    const state = new Float64Array(6);  // centre, velocity after the last step
    const fetch = () => {
      if (f32.buffer !== px.HEAPU8.buffer) f32 = new Float32Array(px.HEAPU8.buffer);
      const pose = getPose(bodyPtr) >> 2;  // PxTransform: q (x, y, z, w), then p
      state[0] = f32[pose + 4]; state[1] = f32[pose + 5]; state[2] = f32[pose + 6];
      const v = getVelocity(bodyPtr) >> 2;
      state[3] = f32[v]; state[4] = f32[v + 1]; state[5] = f32[v + 2];
    };
    const starts = perContact ? new ContactStarts(s) : null;
    const before = Float64Array.from(s.velocity);  // the velocity the step starts from
    const stats = { betaApplied: 0 };
    let fresh = false;
    const n = inner.n;

    return {
      step() {
        if (!perContact) {
          for (let i = 0; i < n; ++i) { scene.simulate(h); scene.fetchResults(true); }
          if (errors.length) check('PhysX while stepping');
          fresh = false;
          return;
        }
        for (let i = 0; i < n; ++i) substep();
      },
      read(out) {
        if (!fresh) fetch();
        for (let i = 0; i < 6; ++i) out[i] = state[i];
      },
      free() {
        if (process.env.BOUNCECHECK_PHYSX_STATS) process.stderr.write(`physx stats: ${JSON.stringify(stats)}\n`);
        lib.errors.sink = null;
        scene.release();
        body.release();
        for (const a of statics) a.release();
        wallMaterial.release();
        ballMaterial.release();
        for (const o of keep) px.destroy(o);
      },
      stats,
    };

    // Per-contact mode: one simulate of h, then beta on the contacts that
    // started pushing in it.
    function substep() {
      scene.simulate(h);
      scene.fetchResults(true);
      if (errors.length) check('PhysX while stepping');
      fetch();
      fresh = true;
      if (events) {
        events = 0;
        const axes = starts.starting(pushed, before);
        if (axes.length) {
          const out = starts.scaled(state.subarray(3, 6), axes);
          state[3] = out[0]; state[4] = out[1]; state[5] = out[2];
          velocity.set_x(out[0]); velocity.set_y(out[1]); velocity.set_z(out[2]);
          body.setLinearVelocity(velocity, true);
          ++stats.betaApplied;
        }
      }
      before[0] = state[3]; before[1] = state[4]; before[2] = state[5];
    }
  },
};

function report(px, s, t, { mu, contactOffset, ccdMaxSeparation, travel, perContact, ccd, inner, settings }) {
  // Measured numbers below: seed-3d, dt 1e-3, per-contact unless said (exact's in brackets).
  const add = (k, v, why) => settings.add(k, v, why);
  add('inner_steps', `${inner.n}${t.inner_steps === 'auto' ? ' (auto)' : ` (given; auto would be ${inner.auto})`}`,
    `simulate(dt / ${inner.n}) per engine step. A PGS floor bounce leaves at alpha (u + |g| h), a gain of about (1 + alpha) |g| h / (alpha u) in speed per bounce; `
    + `predicted for the first three bounces at h = dt (first impact ${+inner.u1.toPrecision(4)} m/s): ${+(100 * inner.predicted).toPrecision(3)}%, auto keeps it within 1%. `
    + 'One simulate per step at dt 0.03: second and third apexes 0.4678 and 0.3198 m (0.4590, 0.3053); auto (6): 0.4602, 0.3074');
  add('solver', t.solver, 'PGS is PhysX\'s default. TGS: second apex 0.1785 m (0.4590): its speculative contact first stops the ball at the wall, then restitution acts on what is left (first floor bounce 0.358 -> 0.159 m/s, e 0.44)');
  add('bounce_threshold', t.bounce_threshold, 'must be > 0. PhysX\'s default 0.2 x speed = 2 m/s: no bounce at all, the ball stops at its first floor contact (5.653 s, restitution 0) and no side wall bounces');
  add('restitution', `ball ${s.alpha}, walls ${s.alpha}, combine ${t.restitution_combine}`, 'both materials carry alpha: average (PhysX\'s default), min and max give alpha; multiply gives alpha^2: floor restitution 0.6405, second apex 0.3135 m');
  add('friction', `ball ${mu}, walls ${mu} (static = dynamic), combine ${t.friction_combine}`,
    perContact ? 'per-contact mode: mu = 0, beta applied after the step that turns the ball' : 'Coulomb mu from [engines] friction on both materials (average, PhysX\'s default, gives mu)');
  add('contact_offset', `${+contactOffset.toPrecision(6)} m per shape (contact distance ${+(2 * contactOffset).toPrecision(6)} m)`,
    `a contact point exists from a separation below the two offsets: the ball turns up to that far before the wall (in the step that would carry it in), or, found later, up to a step's travel inside (largest step travel ${+travel.toPrecision(4)} m). `
    + 'PhysX\'s default 0.02 per shape: the same first five apexes to 0.1 mm here; at a step\'s travel above r / 10 the ball turns up to 4 cm before the wall, a bounce in mid-air');
  add('rest_offset', t.rest_offset, 'PhysX\'s default: the ball rests on the surface');
  add('ccd_max_separation', ccdMaxSeparation, 'a bouncing contact separated by more than this keeps a position bias (the ball approaches by separation / dt first). PhysX\'s default 0.04: no effect while the contact distance is below it');
  add('sleep_threshold', t.sleep_threshold, 'never. PhysX\'s default 5e-5 x speed^2 = 0.005 m^2/s^2: no effect here (the run is bit-identical): PhysX sums the velocity over its sleep window, so a sliding ball never sleeps; one resting in place freezes after 0.4 s');
  add('damping', `linear ${t.linear_damping}, angular ${t.angular_damping}`, 'PhysX\'s defaults are linear 0, angular 0.05: a 1 cm ball rolling at 1.4286 m/s (mu 0.3) slows to 1.4184 m/s in 0.6 s; nothing with mu = 0');
  add('max_angular_velocity', t.max_angular_velocity, 'PhysX\'s default 100 rad/s brakes that rolling ball to 1.0 m/s (100 rad/s x r) within 0.4 s; the seeds spin below 10 rad/s');
  add('iterations', `position ${t.iterations[0]}, velocity ${t.iterations[1]}`, 'PhysX\'s defaults');
  add('ccd', ccd ? 'speculative (eENABLE_SPECULATIVE_CCD)' : 'off', 'the contact offset (auto) covers a step\'s travel up to the skin; [engines] ccd = true turns on PhysX\'s speculative CCD. Its sweep CCD never acts against a plane (PxsCCD.cpp, computeCCDThreshold: a plane\'s threshold is PX_MAX_REAL): measured, a 1 mm ball at 20 m/s with contact_offset 1e-5 sank 9 mm into the wall with eENABLE_CCD as without');
  add('tolerances_scale', 'length 1, speed 10 (PhysX defaults)', 'every threshold derived from it is set explicitly above');
  add('gravity', `(${s.gravity.join(', ')}) m/s^2`, 'the scenario\'s; PxSceneDesc\'s default is none');
  add('walls', '6 static planes (PxPlaneGeometry) at x_i = 0 and x_i = room_i, normals inward', 'a plane is a half-space: a ball however deep still gets a contact. The normals come from f32 quaternions: a 4.4 m/s floor bounce picks up 9e-7 m/s sideways');
  add('ball', `sphere r = ${s.radius} m, mass 1 kg, inertia 2/5 m r^2, rotation ${s.engine.rotation === 'locked' ? 'locked' : 'free'}`, 'the law is per unit mass');
  add('stepping', 'simulate(h) + fetchResults(true), PCM on, stabilization off, no worker threads', 'PhysX defaults (PCM, no stabilization)');
  add('tangential_model', perContact
    ? `per-contact: beta = ${s.beta} after the step in which a touch (eNOTIFY_TOUCH_FOUND) first pushes (eNOTIFY_THRESHOLD_FORCE_FOUND, threshold 0), if the ball moved into the wall at the step's start`
    : `friction: Coulomb mu = ${mu}`,
  perContact ? 'onContact (a filter-data word2 the default filter shader passes on) runs inside fetchResults, after the solver, and the WebIDL binding has no contact-modify callback: the velocity is edited after the step (the protocol\'s ContactStarts)' : 'the scenario\'s [engines] table');
}

export default adapter;
await serve(adapter);
