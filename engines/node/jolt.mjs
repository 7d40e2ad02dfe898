// Jolt Physics (npm jolt-physics 1.1.0, Jolt 5.6.0 compiled to WebAssembly,
// f32) as a bouncecheck simulator: protocol bouncecheck-external/1 through
// host/protocol.mjs (`node jolt.mjs`, or `node jolt.mjs --session`).
//
// The world: one dynamic sphere and six static PlaneShape walls (half-spaces:
// a ball found beyond a wall is still pushed back in). How a Jolt step goes
// (PhysicsSystem::Update, ContactConstraintManager.cpp): gravity is added to
// the velocity first (v += g dt, then the linear damping factor); the narrow
// phase then looks at the positions the step starts from, makes a contact for
// every wall nearer than the speculative contact distance and calls the
// contact listener (OnContactAdded for a new body pair, OnContactPersisted
// for one that had a contact at the previous step) before it sets up the
// contact's constraint; restitution is decided there (normal speed above
// mMinVelocityForRestitution, and reaching the wall within the step) and
// bounces the normal velocity the step started with (the step's gravity is
// cancelled along the normal, so a resting ball gets no bounce whatever the
// threshold); then the solver, x += v dt (a LinearCast body moving more than
// mLinearCastThreshold r is cast against the walls instead, stopped at the
// hit plus the allowed penetration, and bounced there), and the position
// solve (Baumgarte, only for overlap beyond the penetration slop).
//
// Here the speculative distance is 0: a wall gets a contact when the ball
// overlaps it, and every step that moves the ball more than 1% of r is cast,
// so the ball never sinks deeper than 1% of r and bounces at the wall, not
// up to a step before it (Jolt's speculative contacts; docs/engines.md).
//
// Every setting that changes the answer is an [engines.<name>] key with this
// adapter's value as its default (ownKeys below), so a test can put Jolt's own
// default back; each goes into the run's settings with what Jolt's default
// did, measured (docs/engines.md, Jolt).

import { serve, ScenarioError, maxBallSpeed, roomWalls, ownKey, aNumberAtLeast, count0, count1, nonNegative, trueOrFalse } from './host/protocol.mjs';

// Jolt's own defaults (PhysicsSettings.h, BodyCreationSettings.h, MotionProperties).
const JOLT = {
  min_velocity_for_restitution: 1.0,
  linear_damping: 0.05,
  angular_damping: 0.05,
  allow_sleeping: true,
  penetration_slop: 0.02,
  speculative_contact_distance: 0.02,
  baumgarte: 0.2,
  velocity_steps: 10,
  position_steps: 2,
  max_linear_velocity: 500,
  max_angular_velocity: 0.25 * Math.PI * 60,
  wall_friction: 0.2,
  wall_restitution: 0,
  linear_cast_threshold: 0.75,
  linear_cast_max_penetration: 0.25,
  density: 1000,
  body_pair_cache: true,
};

const ownKeys = {
  min_velocity_for_restitution: 'PhysicsSettings::mMinVelocityForRestitution (m/s): slower impacts do not bounce (Jolt: 1)',
  linear_damping: 'the ball\'s linear damping, v *= 1 - c dt every step (Jolt: 0.05)',
  angular_damping: 'the ball\'s angular damping (Jolt: 0.05)',
  allow_sleeping: 'whether the ball may fall asleep (Jolt: true)',
  penetration_slop: 'PhysicsSettings::mPenetrationSlop (m): overlap the position solve leaves alone; also the CCD cast\'s allowed penetration (Jolt: 0.02)',
  speculative_contact_distance: 'PhysicsSettings::mSpeculativeContactDistance (m): walls nearer than this get a contact (Jolt: 0.02)',
  baumgarte: 'PhysicsSettings::mBaumgarte: fraction of the overlap (beyond the slop) removed per step (Jolt: 0.2)',
  velocity_steps: 'PhysicsSettings::mNumVelocitySteps (Jolt: 10)',
  position_steps: 'PhysicsSettings::mNumPositionSteps (Jolt: 2)',
  max_linear_velocity: 'the ball\'s speed cap, m/s (Jolt: 500)',
  max_angular_velocity: 'the ball\'s spin cap, rad/s (Jolt: 0.25 pi 60 = 47.1)',
  wall_friction: 'the walls\' friction; Jolt combines sqrt(ball x wall) (Jolt: 0.2; here: the ball\'s mu)',
  wall_restitution: 'the walls\' restitution; Jolt combines max(ball, wall) (Jolt: 0; here: alpha)',
  linear_cast_threshold: 'PhysicsSettings::mLinearCastThreshold, fraction of r a step must move for the CCD cast (Jolt: 0.75)',
  linear_cast_max_penetration: 'PhysicsSettings::mLinearCastMaxPenetration, fraction of r the CCD cast may leave inside a wall (Jolt: 0.25)',
  body_pair_cache: 'PhysicsSettings::mUseBodyPairContactCache: reuse last step\'s contact while the ball moved < 1 mm and turned < 2 degrees (Jolt: true)',
  ball_mass: 'the ball\'s mass, kg; its inertia is a solid sphere\'s (Jolt: density 1000, 4.19 g for r = 1 cm; here 1/r^2 kg, inertia 0.4 kg m^2)',
};

function fail(message) { throw new ScenarioError(message); }

function build(J, s, settings) {
  const e = s.engine;
  const d = 3;
  if (e.tangential_model !== 'friction' && e.tangential_model !== 'per-contact')
    fail(`[engines.jolt] tangential_model must be "friction" or "per-contact" (got ${JSON.stringify(e.tangential_model)})`);
  const perContact = e.tangential_model === 'per-contact';
  if (typeof e.friction !== 'number' || !(e.friction >= 0)) fail('[engines.jolt] friction must be a number >= 0');
  if (e.rotation !== 'free' && e.rotation !== 'locked') fail('[engines.jolt] rotation must be "free" or "locked"');
  if ('ccd' in e && typeof e.ccd !== 'boolean') fail('[engines.jolt] ccd must be true or false');
  const mu = perContact ? 0 : e.friction;
  const dt = s.dt;
  const vmax = maxBallSpeed(s);

  // ---- The chosen values (each one a key; the default is the choice) ----
  // Jolt asks for a positive value; a resting ball is not bounced at any (its
  // bounce target is the velocity before the step's gravity, 0).
  const minRestitutionSpeed = ownKey(s, 'min_velocity_for_restitution', 1e-9, nonNegative);
  const linearDamping = ownKey(s, 'linear_damping', 0, nonNegative);
  const angularDamping = ownKey(s, 'angular_damping', 0, nonNegative);
  const allowSleeping = ownKey(s, 'allow_sleeping', false, trueOrFalse);
  const slop = ownKey(s, 'penetration_slop', Math.min(JOLT.penetration_slop, 0.01 * s.radius), nonNegative);
  const speculative = ownKey(s, 'speculative_contact_distance', 0, nonNegative);
  const baumgarte = ownKey(s, 'baumgarte', JOLT.baumgarte, nonNegative);
  const velocitySteps = ownKey(s, 'velocity_steps', JOLT.velocity_steps, count1);
  const positionSteps = ownKey(s, 'position_steps', JOLT.position_steps, count0);
  const maxLinear = ownKey(s, 'max_linear_velocity', Math.max(JOLT.max_linear_velocity, 2 * vmax), nonNegative);
  const maxAngular = ownKey(s, 'max_angular_velocity', Math.max(JOLT.max_angular_velocity, 2 * vmax / s.radius), nonNegative);
  const wallFriction = ownKey(s, 'wall_friction', mu, nonNegative);
  const wallRestitution = ownKey(s, 'wall_restitution', s.alpha, nonNegative);
  const castThreshold = ownKey(s, 'linear_cast_threshold', 0.01, nonNegative);
  const castPenetration = ownKey(s, 'linear_cast_max_penetration', JOLT.linear_cast_max_penetration, nonNegative);
  const ballMass = ownKey(s, 'ball_mass', 1 / (s.radius * s.radius), aNumberAtLeast(Number.MIN_VALUE));
  const bodyPairCache = ownKey(s, 'body_pair_cache', false, trueOrFalse);
  const ccd = e.ccd ?? true;
  const locked = e.rotation === 'locked';

  // ---- The system ----
  const LAYER_STATIC = 0, LAYER_MOVING = 1;
  const pairFilter = new J.ObjectLayerPairFilterTable(2);
  pairFilter.EnableCollision(LAYER_STATIC, LAYER_MOVING);
  pairFilter.EnableCollision(LAYER_MOVING, LAYER_MOVING);
  const bpStatic = new J.BroadPhaseLayer(0), bpMoving = new J.BroadPhaseLayer(1);
  const bpInterface = new J.BroadPhaseLayerInterfaceTable(2, 2);
  bpInterface.MapObjectToBroadPhaseLayer(LAYER_STATIC, bpStatic);
  bpInterface.MapObjectToBroadPhaseLayer(LAYER_MOVING, bpMoving);
  J.destroy(bpStatic); J.destroy(bpMoving);
  const joltSettings = new J.JoltSettings();
  joltSettings.mMaxBodies = 16;
  joltSettings.mMaxBodyPairs = 64;
  joltSettings.mMaxContactConstraints = 64;
  joltSettings.mObjectLayerPairFilter = pairFilter;
  joltSettings.mBroadPhaseLayerInterface = bpInterface;
  joltSettings.mObjectVsBroadPhaseLayerFilter = new J.ObjectVsBroadPhaseLayerFilterTable(bpInterface, 2, pairFilter, 2);
  const jolt = new J.JoltInterface(joltSettings);  // owns the three filters now
  J.destroy(joltSettings);
  const system = jolt.GetPhysicsSystem();
  const bodies = system.GetBodyInterface();
  const tmp = new J.Vec3(0, 0, 0);
  const tmpR = new J.RVec3(0, 0, 0);
  const free = [];  // what to destroy, besides the interface
  free.push(tmp, tmpR);

  const ps = system.GetPhysicsSettings();
  ps.mMinVelocityForRestitution = minRestitutionSpeed;
  ps.mPenetrationSlop = slop;
  ps.mSpeculativeContactDistance = speculative;
  ps.mBaumgarte = baumgarte;
  ps.mNumVelocitySteps = velocitySteps;
  ps.mNumPositionSteps = positionSteps;
  ps.mAllowSleeping = allowSleeping;
  ps.mUseBodyPairContactCache = bodyPairCache;
  ps.mLinearCastThreshold = castThreshold;
  ps.mLinearCastMaxPenetration = castPenetration;
  system.SetPhysicsSettings(ps);
  tmp.Set(s.gravity[0], s.gravity[1], s.gravity[2]);
  system.SetGravity(tmp);

  // ---- The walls: static half-spaces, x[axis] = offset, solid beyond ----
  const walls = roomWalls(s);
  const halfExtent = 2 * Math.max(...s.room) + 1;
  const wallPointers = [];
  for (const w of walls) {
    // Plane n.x + c = 0 with its solid side where n.x + c < 0: n points into the room.
    const n = [0, 0, 0];
    n[w.axis] = -w.side;
    tmp.Set(n[0], n[1], n[2]);
    const plane = new J.Plane(tmp, w.side > 0 ? w.offset : -w.offset);
    const shape = new J.PlaneShape(plane, null, halfExtent);
    J.destroy(plane);
    tmpR.Set(0, 0, 0);
    const bcs = new J.BodyCreationSettings(shape, tmpR, J.Quat.prototype.sIdentity(), J.EMotionType_Static, LAYER_STATIC);
    bcs.mFriction = wallFriction;
    bcs.mRestitution = wallRestitution;
    const body = bodies.CreateBody(bcs);
    J.destroy(bcs);
    bodies.AddBody(body.GetID(), J.EActivation_DontActivate);
    wallPointers.push(J.getPointer(body));
  }

  // ---- The ball ----
  const sphere = new J.SphereShape(s.radius, null);
  tmpR.Set(s.position[0], s.position[1], s.position[2]);
  const bcs = new J.BodyCreationSettings(sphere, tmpR, J.Quat.prototype.sIdentity(), J.EMotionType_Dynamic, LAYER_MOVING);
  bcs.mFriction = mu;
  bcs.mRestitution = s.alpha;
  bcs.mLinearDamping = linearDamping;
  bcs.mAngularDamping = angularDamping;
  bcs.mAllowSleeping = allowSleeping;
  bcs.mMaxLinearVelocity = maxLinear;
  bcs.mMaxAngularVelocity = maxAngular;
  bcs.mMotionQuality = ccd ? J.EMotionQuality_LinearCast : J.EMotionQuality_Discrete;
  // The law does not depend on the mass; the inertia does, through Jolt's
  // MotionProperties::SetMassProperties: an inertia diagonal whose squared
  // length is at most 1e-12 (a solid sphere of density 1000 with r < 1.5 cm)
  // is taken as a failed decomposition and replaced by the inertia of a 1 m
  // sphere, 10^4 times too large for r = 1 cm: the ball then slides where it
  // should roll. The mass is set so that the inertia is 0.4 kg m^2.
  bcs.mOverrideMassProperties = J.EOverrideMassProperties_CalculateInertia;
  bcs.mMassPropertiesOverride.mMass = ballMass;
  if (locked) bcs.mAllowedDOFs = J.EAllowedDOFs_TranslationX | J.EAllowedDOFs_TranslationY | J.EAllowedDOFs_TranslationZ;
  tmp.Set(s.velocity[0], s.velocity[1], s.velocity[2]);
  bcs.mLinearVelocity = tmp;
  const ball = bodies.CreateBody(bcs);
  J.destroy(bcs);
  bodies.AddBody(ball.GetID(), J.EActivation_Activate);
  const ballPointer = J.getPointer(ball);

  // The state is read straight from Jolt's memory: the body's mPosition (the
  // centre of mass, the sphere's centre) and its motion properties'
  // mLinearVelocity, each found once by matching what the accessors return,
  // then read with no call into the module (a call and its wrapper cost
  // microseconds). If the layout does not match, the accessors are used.
  const F32 = () => J.HEAPF32;
  const motionPointer = J.getPointer(ball.GetMotionProperties());
  function findOffset(base, values) {
    const heap = F32();
    for (let k = 0; k < 64; ++k) {
      const at = (base >> 2) + k;
      if (heap[at] === Math.fround(values[0]) && heap[at + 1] === Math.fround(values[1]) && heap[at + 2] === Math.fround(values[2])) return at;
    }
    return -1;
  }
  // Probe values no field of the body holds by chance, set and found, then
  // the scenario's state put back.
  tmpR.Set(0.123456789, -0.234567891, 0.345678912);
  bodies.SetPosition(ball.GetID(), tmpR, J.EActivation_DontActivate);
  tmp.Set(-0.456789123, 0.567891234, -0.678912345);
  ball.SetLinearVelocity(tmp);
  const p0 = ball.GetPosition();
  const v0 = ball.GetLinearVelocity();
  const posAt = findOffset(ballPointer, [p0.GetX(), p0.GetY(), p0.GetZ()]);
  const velAt = findOffset(motionPointer, [v0.GetX(), v0.GetY(), v0.GetZ()]);
  tmpR.Set(s.position[0], s.position[1], s.position[2]);
  bodies.SetPosition(ball.GetID(), tmpR, J.EActivation_Activate);
  tmp.Set(s.velocity[0], s.velocity[1], s.velocity[2]);
  ball.SetLinearVelocity(tmp);
  const direct = posAt >= 0 && velAt >= 0 && ballPointer % 4 === 0;

  function readVelocity(out) {
    if (direct) { const h = F32(); out[0] = h[velAt]; out[1] = h[velAt + 1]; out[2] = h[velAt + 2]; return; }
    const v = ball.GetLinearVelocity();
    out[0] = v.GetX(); out[1] = v.GetY(); out[2] = v.GetZ();
  }

  // ---- Per-contact mode: beta at the start of each contact, in the listener ----
  let stepIndex = 0;
  let listener = null;
  if (perContact) {
    // The listener runs for every wall Jolt holds a contact with (overlap, a
    // CCD hit, or with speculative contacts on, any wall within that
    // distance), after this step's gravity and before the solver. The ball
    // touches a wall when it overlaps it or reaches it within this step
    // (gap <= v_n dt). A wall touched at this step and not at the previous
    // one starts a contact of the law if the ball moves into it; a resting
    // ball whose normal velocity jitters about 0 while it stays in overlap
    // goes on touching (counted as new contacts, those jitters took 1% of a
    // slide every ~20 steps: 0.052 to 0.016 m/s in 7 s on seed-3d). Then
    // every velocity component normal to none of the walls starting at this
    // step is scaled by beta, once, from the velocity the step had before the
    // first of them (the solver keeps the normal component: the bounce is
    // computed from it).
    const touchedAt = new Array(walls.length).fill(-2);  // the last step at which the ball reached each wall
    const startedAxes = [false, false, false];
    let startedStep = -1;
    const original = new Float64Array(3);
    const v = new Float64Array(3);
    const manifoldClass = J.ContactManifold;
    const depthOf = (manifoldPointer) => J.wrapPointer(manifoldPointer, manifoldClass).get_mPenetrationDepth();
    const onContact = (body1, body2, manifoldPointer) => {
      const other = body1 === ballPointer ? body2 : body1;
      const w = wallPointers.indexOf(other);
      if (w < 0) return;
      const { axis, side } = walls[w];
      readVelocity(v);
      const into = v[axis] * side;  // speed towards the wall, after this step's gravity
      const gap = -depthOf(manifoldPointer);
      if (!(gap <= Math.max(into, 0) * dt)) return;  // apart, and not reaching the wall in this step
      const last = touchedAt[w];
      touchedAt[w] = stepIndex;
      if (last === stepIndex - 1 || last === stepIndex) return;  // a contact that goes on
      if (!(into > 0)) return;  // the law counts a contact the ball moves into
      if (startedStep !== stepIndex) {
        startedStep = stepIndex;
        startedAxes.fill(false);
        original.set(v);
      }
      startedAxes[axis] = true;
      for (let i = 0; i < d; ++i) v[i] = startedAxes[i] ? original[i] : original[i] * s.beta;
      tmp.Set(v[0], v[1], v[2]);
      ball.SetLinearVelocity(tmp);
    };
    listener = new J.ContactListenerJS();
    listener.OnContactValidate = () => J.ValidateResult_AcceptAllContactsForThisBodyPair;
    listener.OnContactAdded = onContact;
    listener.OnContactPersisted = onContact;
    listener.OnContactRemoved = () => {};
    system.SetContactListener(listener);
  }

  // ---- Settings (each why: what Jolt's own value did, measured; docs/engines.md, Jolt) ----
  const add = (key, value, why) => settings.add(key, value, why);
  const mark = (value, key) => (value === JOLT[key] ? ' [Jolt\'s default]' : '');
  add('tangential_model', perContact ? `per-contact: beta = ${s.beta} once at each contact's start, in the contact listener` : `friction: Coulomb mu = ${mu}`,
    perContact ? 'ContactListenerJS OnContactAdded/OnContactPersisted, after the step\'s gravity and before the solver: a wall the ball overlaps or reaches within this step, and did not at the previous one, while moving into it'
      : 'the scenario\'s [engines.<name>] friction');
  add('restitution', `ball ${s.alpha}, walls ${wallRestitution}: combined max = ${Math.max(s.alpha, wallRestitution)}`,
    'Jolt combines restitution as max(ball, wall) (not settable from JS): walls at Jolt\'s 0 give alpha as well (seed-3d: the same trajectory to the bit)');
  add('friction', `ball ${mu}, walls ${wallFriction}: combined sqrt = ${Math.sqrt(mu * wallFriction)}`,
    'Jolt combines friction as sqrt(ball x wall): walls at Jolt\'s 0.2 give sqrt(0.2 mu) (seed-3d friction mode, mu 0.00554: 0.033; second apex 0.4328 m instead of 0.4624)' + mark(wallFriction, 'wall_friction'));
  add('min_velocity_for_restitution', minRestitutionSpeed,
    'Jolt\'s 1 m/s: slower impacts do not bounce; seed-3d\'s first floor impact (0.35 m/s) stops the ball dead (second apex 0.0499 m, at rest from 5.65 s)' + mark(minRestitutionSpeed, 'min_velocity_for_restitution'));
  add('damping', `linear ${linearDamping}, angular ${angularDamping}`,
    'Jolt\'s 0.05 (v *= 1 - 0.05 dt): seed-3d second apex 0.3773 m instead of 0.4589, fifth 0.1092 instead of 0.1528; angular 0.05: a rolling 10 cm ball 0.664 m/s after 5 s instead of 0.713');
  add('sleeping', allowSleeping ? 'allowed' : 'off (system and body)', 'Jolt\'s default lets the ball sleep: seed-3d per-contact froze it at 34.82 s while it slid at 0.061 m/s');
  add('penetration_slop', slop, 'overlap the position solve leaves; also the CCD cast\'s allowed penetration, min(slop, 0.25 r). 1% of r; Jolt\'s 0.02 m lets a cast ball end 6.0 mm inside the floor (seed-3d, dt 0.03)' + mark(slop, 'penetration_slop'));
  add('speculative_contact_distance', speculative,
    'Jolt\'s 0.02 m bounces the ball from where the step starts, up to a step of travel before the wall: seed-3d at dt 0.03 bounces 8.2 mm above the floor; a 1 cm ball in a 0.2 m room at dt 1e-3 comes 3.4% high at its third apex' + mark(speculative, 'speculative_contact_distance'));
  add('linear_cast_threshold', castThreshold, 'a step that moves the ball more than this fraction of r is cast against the walls (CCD), so no step sinks it deeper than 1% of r; Jolt\'s 0.75 casts no step of seed-3d at dt 0.03 (6.0 mm deep)' + mark(castThreshold, 'linear_cast_threshold'));
  add('linear_cast_max_penetration', castPenetration, 'with the slop, how deep a cast leaves the ball' + mark(castPenetration, 'linear_cast_max_penetration'));
  add('ccd', ccd ? 'LinearCast motion quality' : 'Discrete motion quality (Jolt\'s default)', 'with Discrete, seed-3d at dt 0.03 ends 6.0 mm inside the floor (LinearCast: 0.5 mm)');
  add('body_pair_cache', bodyPairCache, 'Jolt\'s cache keeps a resting contact\'s points and normal in the ball\'s frame while it turns less than 2 degrees: a frictionless ball (mu 0, rotation free) sliding on the floor at 0.02 m/s spins up and speeds up to 0.189 m/s in 3 s (g 9.81; without the cache it keeps 0.02)' + mark(bodyPairCache, 'body_pair_cache'));
  add('baumgarte', baumgarte, 'position solve factor' + mark(baumgarte, 'baumgarte'));
  add('solver_iterations', `velocity ${velocitySteps}, position ${positionSteps}`, 'Jolt\'s 10 and 2' + (velocitySteps === JOLT.velocity_steps && positionSteps === JOLT.position_steps ? ' [Jolt\'s defaults]' : ''));
  add('speed_caps', `linear ${maxLinear} m/s, angular ${maxAngular} rad/s`,
    'at least twice what the law allows; Jolt\'s 47.1 rad/s stops a 1 cm ball rolling at 0.471 m/s instead of 0.714 (Jolt\'s 500 m/s not reached here)');
  add('ball_mass', ballMass, `inertia ${(0.4 * ballMass * s.radius * s.radius).toPrecision(3)} kg m^2 (the law does not depend on the mass); at Jolt's density 1000 a ball under 1.5 cm gets the inertia of a 1 m sphere (MotionProperties::SetMassProperties, near-zero diagonal): a 1 cm ball slides to a stop in 0.2 s instead of rolling at 0.714 m/s`);
  add('rotation', locked ? 'locked (allowed DOFs: translation only)' : 'free', 'scenario [engines.<name>] rotation');
  add('gravity', `(${s.gravity.join(', ')}) m/s^2`, 'the scenario\'s (Jolt\'s default is (0, -9.81, 0))');
  add('walls', `six static PlaneShapes (half-spaces), half extent ${halfExtent} m`, 'exact planes; a ball beyond one is pushed back');
  add('state_read', direct ? 'from Jolt\'s memory (body mPosition, motion mLinearVelocity)' : 'through Body::GetPosition / GetLinearVelocity', 'no call into the module per step');

  return {
    step() { ++stepIndex; jolt.Step(dt, 1); },
    read(out) {
      if (direct) {
        const h = F32();
        out[0] = h[posAt]; out[1] = h[posAt + 1]; out[2] = h[posAt + 2];
        out[3] = h[velAt]; out[4] = h[velAt + 1]; out[5] = h[velAt + 2];
        return;
      }
      const p = ball.GetPosition();
      out[0] = p.GetX(); out[1] = p.GetY(); out[2] = p.GetZ();
      const v = ball.GetLinearVelocity();
      out[3] = v.GetX(); out[4] = v.GetY(); out[5] = v.GetZ();
    },
    free() {
      for (const o of free) J.destroy(o);
      J.destroy(jolt);  // the bodies, shapes and the listener's registration go with the system
      if (listener) J.destroy(listener);
    },
  };
}

export const adapter = {
  name: 'jolt',
  dimensions: [3],
  precision: 'f32',
  packages: () => ['jolt-physics'],
  ownKeys,
  async load() { return (await import('jolt-physics/wasm')).default(); },
  version: () => 'Jolt Physics 5.6.0 (the JoltPhysics.js 1.1.0 build)',
  build,
};

await serve(adapter);
