// Havok (npm @babylonjs/havok 1.3.14, Havok Physics for the Web compiled to
// WebAssembly, f32) as a bouncecheck simulator: protocol
// bouncecheck-external/1 through host/protocol.mjs (`node havok.mjs`, or
// `node havok.mjs --session`).
//
// Havok for the Web is closed source: everything below about how a step goes
// was measured, not read. A ball moving into a wall is stopped at it in the
// step it would cross it (a speculative contact: the step ends with the ball
// on the wall, its normal velocity about 0), and bounces at the next step with
// restitution times the speed it came in with; COLLISION_STARTED is raised
// after the stopping step, carrying the impulse (an impulse event: a wall
// merely near raises none). When the crossing falls in the last few percent
// of a step, the step before is cut to land the ball exactly on the wall and
// the bounce uses that lower speed (up to 10% less). A ball sliding on a wall
// slower than about 0.1 m/s is braked at about 0.03 |g| even with mu = 0.
// The world: one dynamic sphere and six static boxes whose inner faces are
// the walls, each as thick as the room is large.
//
// Every setting that changes the answer is an [engines.<name>] key with this
// adapter's value as its default (ownKeys below), so a test can put Havok's
// own default back; each goes into the run's settings with what Havok's
// default did, measured (docs/engines.md, Havok).

import fs from 'node:fs';
import { createRequire } from 'node:module';
import { serve, ScenarioError, maxBallSpeed, roomWalls, ContactStarts, ownKey, nonNegative, oneOf, trueOrFalse } from './host/protocol.mjs';

// Havok's own defaults (HP_World_Create, HP_Body_Create, HP_Shape_Create*, measured by reading them back).
const HAVOK = {
  ideal_step_time: 1 / 60,
  linear_damping: 0,
  angular_damping: 0.1,
  always_active: false,
  max_linear_velocity: 200,
  max_angular_velocity: 100,
  wall_friction: 0.5,
  wall_restitution: 0,
  combine: 'GEOMETRIC_MEAN',
};

const COMBINES = ['GEOMETRIC_MEAN', 'MINIMUM', 'MAXIMUM', 'ARITHMETIC_MEAN', 'MULTIPLY'];
const COMBINE_RULE = oneOf(...COMBINES);  // the kind of the *_combine keys

const ownKeys = {
  ideal_step_time: 'HP_World_SetIdealStepTime (s): the step the solver\'s stiffness is tuned for; 0 turns the adjustment off (Havok: 1/60; here: dt)',
  linear_damping: 'the ball\'s linear damping (Havok: 0)',
  angular_damping: 'the ball\'s angular damping (Havok: 0.1)',
  always_active: 'the ball never sleeps (ActivationControl ALWAYS_ACTIVE; Havok: SIMULATION_CONTROLLED, false here)',
  max_linear_velocity: 'the world\'s speed limit, m/s (Havok: 200)',
  max_angular_velocity: 'the world\'s spin limit, rad/s (Havok: 100)',
  wall_friction: 'the walls\' static and dynamic friction (Havok: 0.5; here: the ball\'s mu)',
  wall_restitution: 'the walls\' restitution (Havok: 0; here: alpha)',
  friction_combine: `how two friction values combine, both materials: ${COMBINES.join(', ')} (Havok: GEOMETRIC_MEAN)`,
  restitution_combine: `how two restitution values combine, both materials (Havok: GEOMETRIC_MEAN)`,
};

function fail(message) { throw new ScenarioError(message); }

// Every HP_ call returns [Result, ...]: anything but RESULT_OK fails the run with the call's name.
function checked(H) {
  const ok = H.Result.RESULT_OK;
  return (name, ...args) => {
    const r = H[name](...args);
    const result = Array.isArray(r) ? r[0] : r;
    if (result !== ok) fail(`${name} failed: ${Object.keys(H.Result).find((k) => H.Result[k] === result) ?? String(result)}`);
    return Array.isArray(r) ? r[1] : undefined;
  };
}

// The places in the module's memory that hold three floats the way `set`
// writes them: a probe is set, then a second one, then `other` overwrites
// the call's argument copies; what still holds the second probe is a
// candidate (the engine's own copies of the state).
// Where the velocity was found in the last world this process built. A new
// world's ball lands at the same place (measured), so that place is tried
// first: scanning the whole heap (4 M floats) cost 10-20 ms a run, as much as
// 15% of a seed run's steps at dt = 1e-3.
let lastVelocityPlace = -1;

function candidates(H, set, other) {
  const a = [0.123456789, -0.234567891, 0.345678912].map(Math.fround);
  const b = [-0.456789123, 0.567891234, -0.678912345].map(Math.fround);
  const holds = (f, i, v) => f[i] === v[0] && f[i + 1] === v[1] && f[i + 2] === v[2];
  set(a);
  let f = H.HEAPF32;
  const hinted = lastVelocityPlace >= 0 && lastVelocityPlace + 2 < f.length && holds(f, lastVelocityPlace, a);
  const hits = [];
  if (hinted) hits.push(lastVelocityPlace);
  else for (let i = 0; i + 2 < f.length; ++i) if (holds(f, i, a)) hits.push(i);
  set(b);
  other();
  f = H.HEAPF32;
  const places = hits.filter((i) => holds(f, i, b));
  // A hint that failed the second test: scan after all.
  return hinted && places.length === 0 ? (lastVelocityPlace = -1, candidates(H, set, other)) : places;
}

function build(H, s, settings) {
  const e = s.engine;
  const call = checked(H);
  if (e.tangential_model !== 'friction' && e.tangential_model !== 'per-contact')
    fail(`[engines.havok] tangential_model must be "friction" or "per-contact" (got ${JSON.stringify(e.tangential_model)})`);
  const perContact = e.tangential_model === 'per-contact';
  if (typeof e.friction !== 'number' || !(e.friction >= 0)) fail('[engines.havok] friction must be a number >= 0');
  if (e.rotation !== 'free' && e.rotation !== 'locked') fail('[engines.havok] rotation must be "free" or "locked"');
  if ('ccd' in e && e.ccd !== true) fail('[engines.havok] ccd: Havok exposes no switch: its speculative contacts are always on (ccd = true or absent)');
  const mu = perContact ? 0 : e.friction;
  const dt = s.dt;
  const vmax = maxBallSpeed(s);
  const locked = e.rotation === 'locked';

  const idealStep = ownKey(s, 'ideal_step_time', dt, nonNegative);
  const linearDamping = ownKey(s, 'linear_damping', 0, nonNegative);
  const angularDamping = ownKey(s, 'angular_damping', 0, nonNegative);
  const alwaysActive = ownKey(s, 'always_active', true, trueOrFalse);
  const maxLinear = ownKey(s, 'max_linear_velocity', Math.max(HAVOK.max_linear_velocity, 2 * vmax), nonNegative);
  const maxAngular = ownKey(s, 'max_angular_velocity', Math.max(HAVOK.max_angular_velocity, 2 * vmax / s.radius), nonNegative);
  const wallFriction = ownKey(s, 'wall_friction', mu, nonNegative);
  const wallRestitution = ownKey(s, 'wall_restitution', s.alpha, nonNegative);
  const frictionCombine = ownKey(s, 'friction_combine', HAVOK.combine, COMBINE_RULE);
  const restitutionCombine = ownKey(s, 'restitution_combine', HAVOK.combine, COMBINE_RULE);
  const FC = H.MaterialCombine[frictionCombine], RC = H.MaterialCombine[restitutionCombine];

  // ---- The world ----
  const world = call('HP_World_Create');
  const owned = { shapes: [], bodies: [] };
  call('HP_World_SetGravity', world, [s.gravity[0], s.gravity[1], s.gravity[2]]);
  call('HP_World_SetIdealStepTime', world, idealStep);
  call('HP_World_SetSpeedLimit', world, maxLinear, maxAngular);

  // ---- The walls: static boxes whose inner faces are the walls ----
  const walls = roomWalls(s);
  const thickness = Math.max(...s.room);
  const wallIds = [];
  for (const w of walls) {
    const centre = s.room.map((l) => l / 2);
    centre[w.axis] = w.side < 0 ? -thickness / 2 : s.room[w.axis] + thickness / 2;
    const extents = s.room.map((l) => l + 2 * thickness);
    extents[w.axis] = thickness;
    const shape = call('HP_Shape_CreateBox', centre, [0, 0, 0, 1], extents);
    owned.shapes.push(shape);
    call('HP_Shape_SetMaterial', shape, [wallFriction, wallFriction, wallRestitution, FC, RC]);
    const body = call('HP_Body_Create');
    owned.bodies.push(body);
    call('HP_Body_SetShape', body, shape);
    call('HP_Body_SetMotionType', body, H.MotionType.STATIC);
    call('HP_World_AddBody', world, body, false);
    wallIds.push(body[0]);
  }

  // ---- The ball ----
  const sphere = call('HP_Shape_CreateSphere', [0, 0, 0], s.radius);
  owned.shapes.push(sphere);
  call('HP_Shape_SetMaterial', sphere, [mu, mu, s.alpha, FC, RC]);
  const ball = call('HP_Body_Create');
  owned.bodies.push(ball);
  call('HP_Body_SetShape', ball, sphere);
  call('HP_Body_SetMotionType', ball, H.MotionType.DYNAMIC);
  const mass = call('HP_Shape_BuildMassProperties', sphere);
  if (locked) mass[2] = [0, 0, 0];  // zero inertia: Havok keeps the angular velocity at 0 (measured)
  call('HP_Body_SetMassProperties', ball, mass);
  call('HP_Body_SetLinearDamping', ball, linearDamping);
  call('HP_Body_SetAngularDamping', ball, angularDamping);
  call('HP_Body_SetQTransform', ball, [[s.position[0], s.position[1], s.position[2]], [0, 0, 0, 1]]);
  call('HP_World_AddBody', world, ball, false);
  call('HP_Body_SetActivationControl', ball, alwaysActive ? H.ActivationControl.ALWAYS_ACTIVE : H.ActivationControl.SIMULATION_CONTROLLED);
  const ballId = ball[0];

  // ---- Reading the state without a call per step ----
  // The centre: the body buffer's world transform (HP_World_GetBodyBuffer,
  // HP_Body_GetWorldTransformOffset: a 3x4 matrix of floats, the translation
  // last), as Babylon's Havok plugin reads it; valid while no body is added.
  // The velocity: of the places in memory that follow
  // HP_Body_SetLinearVelocity (found once, by probes), the one that holds
  // what HP_Body_GetLinearVelocity returns after the steps; until a step
  // tells them apart (and for good if none does) the call is used.
  const bodyBuffer = call('HP_World_GetBodyBuffer', world);
  const posAt = ((bodyBuffer + call('HP_Body_GetWorldTransformOffset', ball)) >> 2) + 12;
  let velocityPlaces = candidates(H, (v) => call('HP_Body_SetLinearVelocity', ball, v),
    // the same call on a static wall (no effect on it) overwrites the argument's copies
    () => call('HP_Body_SetLinearVelocity', owned.bodies[0], [0.5, 0.25, 0.125]));
  call('HP_Body_SetLinearVelocity', ball, [s.velocity[0], s.velocity[1], s.velocity[2]]);
  call('HP_Body_SetAngularVelocity', ball, [0, 0, 0]);
  const holds = (i, v) => H.HEAPF32[i] === Math.fround(v[0]) && H.HEAPF32[i + 1] === Math.fround(v[1]) && H.HEAPF32[i + 2] === Math.fround(v[2]);
  const directPosition = holds(posAt, s.position);
  let velAt = -1;
  let readsByCall = 0;
  let describeStateRead = () => {};
  function readVelocity(out, at) {
    if (velAt >= 0) { const f = H.HEAPF32; out[at] = f[velAt]; out[at + 1] = f[velAt + 1]; out[at + 2] = f[velAt + 2]; return; }
    const v = call('HP_Body_GetLinearVelocity', ball);
    out[at] = v[0]; out[at + 1] = v[1]; out[at + 2] = v[2];
    ++readsByCall;
    if (velocityPlaces.length > 0) {
      velocityPlaces = velocityPlaces.filter((i) => holds(i, v));
      if (velocityPlaces.length === 1 && readsByCall >= 2) { velAt = lastVelocityPlace = velocityPlaces[0]; describeStateRead(); }
    }
  }

  // ---- Per-contact mode: after the step, from the collision events ----
  const velocity = new Float64Array(3);  // after the last step: the next step's `before`
  velocity.set(s.velocity);
  let afterStep = null;
  if (perContact) {
    // Only the ball raises events (its event mask: COLLISION_STARTED and
    // _FINISHED). A wall with a COLLISION_STARTED in this step (an impulse
    // began) starts a contact of the law if the ball moved into it at the
    // step's start (ContactStarts, on the velocity read after the previous
    // step); the velocity, the stopped ball's, is then scaled off the
    // starting walls' normals by beta, and Havok bounces the normal
    // component at the next step from what it stored (a velocity set here
    // does not change the bounce, measured). One call per step
    // (HP_World_GetCollisionEvents); the events are read from memory.
    call('HP_Body_SetEventMask', ball, H.EventType.COLLISION_STARTED.value | H.EventType.COLLISION_FINISHED.value);
    const starts = new ContactStarts(s);
    const touching = new Array(walls.length).fill(false);
    const apart = new Array(walls.length).fill(false);
    const worldAddress = Number(world[0]);
    const STARTED = H.EventType.COLLISION_STARTED.value;
    const before = new Float64Array(3);
    afterStep = () => {
      before.set(velocity);
      readVelocity(velocity, 0);
      // [RESULT_FAIL, 0] when the step raised none.
      let event = H.HP_World_GetCollisionEvents(world)[1];
      if (!event) return;
      touching.fill(false);
      for (; event; event = H.HP_World_GetNextCollisionEvent(worldAddress, event)) {
        // The event's layout (Babylon's havokPlugin.ts, CollisionEvent.readToRef):
        // int32 type at 0, body A's id at int32 2, body B's at int32 18.
        const i32 = event >> 2;
        if (H.HEAP32[i32] !== STARTED) continue;
        const a = BigInt(H.HEAP32[i32 + 2]), b = BigInt(H.HEAP32[i32 + 18]);
        const other = a === ballId ? b : b === ballId ? a : null;
        const w = other === null ? -1 : wallIds.indexOf(other);
        if (w >= 0) touching[w] = true;
      }
      const axes = starts.starting(touching, before);
      starts.starting(apart, before);  // each COLLISION_STARTED is a start of its own, even right after another
      if (axes.length === 0) return;
      const scaled = starts.scaled(velocity, axes);
      call('HP_Body_SetLinearVelocity', ball, scaled);
      velocity.set(scaled);
    };
  }

  // ---- Settings (each why: what Havok's own value did, measured; docs/engines.md, Havok) ----
  const add = (key, value, why) => settings.add(key, value, why);
  const mark = (value, key) => (value === HAVOK[key] ? ' [Havok\'s default]' : '');
  add('tangential_model', perContact ? `per-contact: beta = ${s.beta} once at each contact's start, after the step` : `friction: Coulomb mu = ${mu} (static = dynamic)`,
    perContact ? 'Havok raises COLLISION_STARTED after the step that stopped the ball at the wall and bounces it at the next step; the velocity is scaled then (protocol ContactStarts); it has no contact hook inside the step'
      : 'the scenario\'s [engines.<name>] friction');
  add('restitution', `ball ${s.alpha}, walls ${wallRestitution}, ${restitutionCombine}`,
    'both materials carry alpha, so the rule gives alpha; walls at Havok\'s 0 with its geometric mean give 0 (seed-3d: at rest from 5.67 s); MULTIPLY would give alpha^2 (second apex 0.3115 m instead of 0.4586)' + mark(restitutionCombine, 'combine'));
  add('friction', `ball ${mu}, walls ${wallFriction} (static and dynamic), ${frictionCombine}`,
    'both materials carry mu; walls at Havok\'s 0.5 give sqrt(0.5 mu) (seed-3d friction mode, mu 0.00554: 0.053; second apex 0.4104 m instead of 0.4586)' + mark(frictionCombine, 'combine'));
  add('ideal_step_time', idealStep, 'the step Havok tunes its solver for; with Havok\'s 1/60 at dt 1e-3, 10% of impact phases (the wall crossed late in a step) lose up to 10% of the bounce speed (2.5% of phases with dt), and a 1 cm ball in a 0.2 m room comes 5.5% low at its third apex' + mark(idealStep, 'ideal_step_time'));
  add('damping', `linear ${linearDamping}, angular ${angularDamping}`, 'Havok\'s angular 0.1: a 10 cm ball rolling on the floor, 0.619 m/s after 5 s instead of 0.714');
  add('sleeping', alwaysActive ? 'off (ActivationControl ALWAYS_ACTIVE)' : 'Havok\'s (SIMULATION_CONTROLLED)', 'Havok\'s default froze the seed-3d ball mid-air at 1.71 s (z 0.695 m, moving at 0.25 m/s)');
  add('speed_limits', `linear ${maxLinear} m/s, angular ${maxAngular} rad/s`, 'at least twice what the law allows; Havok\'s 100 rad/s holds a 5 mm ball rolling at 0.488 m/s instead of 0.714 (200 m/s not reached here)');
  add('ccd', 'speculative contacts (always on; no switch)', 'the ball is stopped at the wall within the step it would cross it');
  add('rotation', locked ? 'locked (zero inertia)' : 'free', 'scenario [engines.<name>] rotation');
  add('gravity', `(${s.gravity.join(', ')}) m/s^2`, 'the scenario\'s');
  add('walls', `six static boxes ${thickness} m thick, inner faces on the walls`, 'Havok has no plane shape; a box face is exact (a dropped ball rests at r to 1e-7 m)');
  const stateRead = { key: 'state_read', value: '', why: 'no call into the module per step (each costs about 1 us)' };
  describeStateRead = () => {
    stateRead.value = `centre from the body buffer${directPosition ? '' : ' (no match: by HP_Body_GetQTransform)'}, velocity ${velAt >= 0 ? `from the engine's memory after ${readsByCall} reads by HP_Body_GetLinearVelocity` : 'by HP_Body_GetLinearVelocity'}`;
  };
  describeStateRead();
  settings.list.push(stateRead);

  return {
    step() {
      H.HP_World_Step(world, dt);
      if (afterStep) afterStep();
    },
    read(out) {
      if (directPosition) { const f = H.HEAPF32; out[0] = f[posAt]; out[1] = f[posAt + 1]; out[2] = f[posAt + 2]; }
      else { const p = call('HP_Body_GetQTransform', ball)[0]; out[0] = p[0]; out[1] = p[1]; out[2] = p[2]; }
      readVelocity(out, 3);
    },
    free() {
      H.HP_World_Release(world);
      for (const b of owned.bodies) H.HP_Body_Release(b);
      for (const sh of owned.shapes) H.HP_Shape_Release(sh);
    },
  };
}

export const adapter = {
  name: 'havok',
  dimensions: [3],
  precision: 'f32',
  packages: () => ['@babylonjs/havok'],
  ownKeys,
  async load() {
    // The ESM build fetches its .wasm by URL, which Node refuses for file://:
    // it is handed the bytes instead.
    const require = createRequire(import.meta.url);
    const file = require.resolve('@babylonjs/havok/lib/esm/HavokPhysics.wasm');
    const { default: HavokPhysics } = await import('@babylonjs/havok');
    return HavokPhysics({ wasmBinary: fs.readFileSync(file) });
  },
  version: () => 'Havok Physics for the Web (the @babylonjs/havok 1.3.14 build)',
  build,
};

await serve(adapter);
