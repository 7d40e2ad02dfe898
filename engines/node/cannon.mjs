// cannon-es 0.20.0 (npm cannon-es, plain JavaScript, so f64) as a bouncecheck
// simulator: protocol bouncecheck-external/1 through host/protocol.mjs
// (`node cannon.mjs`, or `node cannon.mjs --session`).
//
// How a step goes (dist/cannon-es.js, World.internalStep, lines 12553-12870):
// gravity goes into the force, the narrow phase runs on the positions the last
// step left (sphere-plane makes a contact only once the ball touches or
// overlaps the plane, spherePlane 10645-10680: no speculative contact, no
// CCD), a body's `collide` event fires for a pair that was not in contact last
// step (12704-12712), the Gauss-Seidel SPOOK solve (GSSolver.solve, 9887-9979)
// adds its impulses, then damping v *= (1 - d)^dt (12812-12826), then
// semi-implicit Euler (Body.integrate, 3887-3935).
//
// The contact's right-hand side (ContactEquation.computeB, 5995-6038) is
//   B = -a g - b (1 + e) u0 - h G M^-1 f,
//   a = 4 / (h (1 + 4 d)), b = 4 d / (1 + 4 d), eps = 4 / (h^2 k (1 + 4 d))
// (Equation.setSpookParams, 5817-5824; k stiffness, d relaxation, g the
// signed gap, negative when overlapping, u0 the normal velocity before this
// step's gravity). One contact on one body: the solve changes u by
// B / (1 + eps m) (m the ball's mass), and the step's gravity, in B and again
// in the integration, cancels out. So the ball leaves at e_eff |u0|,
//   e_eff = ((1 + e) b - 1 + 4 (1 - b) phi) with eps m small,
// phi = overlap / (h |u0|) in [0, 1) (the ball is found up to a step inside):
// restitution is multiplied by b < 1 and the Baumgarte term a g adds up to
// 4 (1 - b) |u0|. With cannon's relaxation 3, e = 0.8 gives 0.66-0.97 by the
// phase of the impact in the step; 1000 narrows it to 0.7996-0.8006
// (docs/engines.md, cannon, finding C1). The relaxation is this adapter's
// main setting (`contact_relaxation`), with a stiffness high enough that
// eps m stays negligible for any ball (`contact_stiffness`).
//
// The world: one dynamic sphere and six static Planes (or boxes: `walls`).
//
// Every setting that changes the answer is an [engines.<name>] key with this
// adapter's value as its default (ownKeys below), so a test can put cannon's
// own default back; each goes into the run's settings with what cannon's
// default did, measured (docs/engines.md, cannon).

import { createRequire } from 'node:module';
import { serve, ScenarioError, roomWalls, movesIntoWall, ownKey, count1, nonNegative, positive, oneOf, trueOrFalse } from './host/protocol.mjs';

// cannon-es's own defaults (ContactMaterial 6672-6690 and World 12217-12220;
// GSSolver 9878-9879; Body 3394-3403, angularDamping 3438; World 12184-12188).
const CANNON = {
  contact_stiffness: 1e7,
  contact_relaxation: 3,
  friction_stiffness: 1e7,
  friction_relaxation: 3,
  iterations: 10,
  tolerance: 1e-7,
  linear_damping: 0.01,
  angular_damping: 0.01,
  allow_sleep: false,
  quat_normalize_fast: false,
  walls: 'plane',
  inertia: 'box',
  friction_gravity: 'gravity',
};

const ownKeys = {
  restitution: 'the contact\'s restitution (the world\'s default ContactMaterial; cannon: 0; here: alpha)',
  contact_stiffness: 'the contact equation\'s SPOOK stiffness k (ContactMaterial contactEquationStiffness; cannon: 1e7)',
  contact_relaxation: 'the contact equation\'s SPOOK relaxation d, in steps (contactEquationRelaxation; cannon: 3)',
  friction_stiffness: 'the friction equations\' SPOOK stiffness (frictionEquationStiffness; cannon: 1e7)',
  friction_relaxation: 'the friction equations\' SPOOK relaxation (frictionEquationRelaxation; cannon: 3)',
  iterations: 'the Gauss-Seidel solver\'s iterations per step (GSSolver.iterations; cannon: 10)',
  tolerance: 'the solver stops once an iteration\'s total |delta lambda| is below it (GSSolver.tolerance; cannon: 1e-7)',
  linear_damping: 'the ball\'s linear damping: v *= (1 - d)^dt each step (Body linearDamping; cannon: 0.01)',
  angular_damping: 'the ball\'s angular damping, as linear_damping (Body angularDamping; cannon: 0.01)',
  allow_sleep: 'the world lets bodies sleep (World allowSleep; cannon: false; the ball\'s own limits are cannon\'s: 0.1 m/s for 1 s)',
  quat_normalize_fast: 'normalise the orientation by the first-order fast formula (World quatNormalizeFast; cannon: false)',
  walls: 'the walls\' shape: "plane" (six static Planes) or "box" (six static boxes, inner faces on the walls) (cannon has no room: plane, as its examples build floors)',
  inertia: 'the ball\'s moment of inertia: "sphere" (2/5 m r^2, Sphere.calculateLocalInertia) or "box" (cannon: Body.updateMassProperties gives every body its bounding box\'s, 2/3 m r^2 for a ball)',
  friction_gravity: 'what bounds each friction impulse, mu |G| m per step (createFrictionEquationsFromContact): "gravity-dt" (G = g dt: Coulomb\'s mu m g dt for a ball resting on a floor) or "gravity" (cannon: G = g, a bound in impulse units 1/dt times Coulomb\'s)',
  density: 'the ball\'s density in kg/m^3: its mass is density times its volume (cannon: a Body has mass 0, static, unless given one; here 1000). The SPOOK softness eps is in 1/kg, so the mass decides how much a finite stiffness softens the contact',
};

function fail(message) { throw new ScenarioError(message); }

function build(CANNON_, s, settings) {
  const e = s.engine;
  const perContact = e.tangential_model === 'per-contact';
  if ('ccd' in e && e.ccd !== false) fail('[engines.cannon] ccd: cannon-es has none (contacts exist only while the shapes touch): ccd = false or absent');
  const mu = perContact ? 0 : e.friction;
  const locked = e.rotation === 'locked';

  const restitution = ownKey(s, 'restitution', s.alpha, nonNegative);
  const stiffness = ownKey(s, 'contact_stiffness', 1e12, positive);
  const relaxation = ownKey(s, 'contact_relaxation', 1000, positive);
  const frictionStiffness = ownKey(s, 'friction_stiffness', CANNON.friction_stiffness, positive);
  const frictionRelaxation = ownKey(s, 'friction_relaxation', CANNON.friction_relaxation, positive);
  const iterations = ownKey(s, 'iterations', CANNON.iterations, count1);
  const tolerance = ownKey(s, 'tolerance', CANNON.tolerance, nonNegative);
  const linearDamping = ownKey(s, 'linear_damping', 0, nonNegative);
  const angularDamping = ownKey(s, 'angular_damping', 0, nonNegative);
  const allowSleep = ownKey(s, 'allow_sleep', CANNON.allow_sleep, trueOrFalse);
  const quatNormalizeFast = ownKey(s, 'quat_normalize_fast', CANNON.quat_normalize_fast, trueOrFalse);
  const wallShape = ownKey(s, 'walls', CANNON.walls, oneOf('plane', 'box'));
  const density = ownKey(s, 'density', 1000, positive);
  const inertia = ownKey(s, 'inertia', 'sphere', oneOf('sphere', 'box'));
  const frictionGravity = ownKey(s, 'friction_gravity', 'gravity-dt', oneOf('gravity-dt', 'gravity'));
  if (linearDamping >= 1 || angularDamping >= 1) fail('[engines.cannon] linear_damping and angular_damping must be below 1 ((1 - d)^dt)');

  const { World, Body, Sphere, Plane, Box, Vec3, Quaternion, GSSolver } = CANNON_;
  const solver = new GSSolver();
  solver.iterations = iterations;
  solver.tolerance = tolerance;
  const world = new World({ gravity: new Vec3(...s.gravity), allowSleep, quatNormalizeFast, quatNormalizeSkip: 0, solver });
  // The friction equations' bound is mu |frictionGravity| m_reduced, compared
  // with lambda, an impulse (GSSolver.solve 9946-9952; addToWlambda adds
  // invMass lambda, 5938): with cannon's world gravity it lets a step
  // take mu |g| off the sliding speed, 1/dt times Coulomb's mu |g| dt.
  if (frictionGravity === 'gravity-dt') world.frictionGravity = new Vec3(...s.gravity.map((g) => g * s.dt));

  // ---- One contact material for every pair: no Material on any body, so
  // the world's default ContactMaterial applies (Narrowphase.getContacts 10595,
  // createContactEquation 10424-10433) and nothing is multiplied by a
  // material's own restitution or friction. ----
  const cm = world.defaultContactMaterial;
  cm.restitution = restitution;
  cm.friction = mu;
  cm.contactEquationStiffness = stiffness;
  cm.contactEquationRelaxation = relaxation;
  cm.frictionEquationStiffness = frictionStiffness;
  cm.frictionEquationRelaxation = frictionRelaxation;

  // ---- The walls ----
  const walls = roomWalls(s);
  const thickness = Math.max(...s.room);
  const wallBodies = [];
  for (const w of walls) {
    const body = new Body({ mass: 0, type: Body.STATIC });
    if (wallShape === 'plane') {
      // A Plane's normal is its local +z (spherePlane 10649-10651): turn it to point into the room.
      const normal = [0, 0, 0];
      normal[w.axis] = -w.side;
      const q = new Quaternion();
      q.setFromVectors(new Vec3(0, 0, 1), new Vec3(...normal));
      body.addShape(new Plane());
      body.quaternion.copy(q);
      const at = [0, 0, 0];
      at[w.axis] = w.side < 0 ? 0 : s.room[w.axis];
      body.position.set(...at);
    } else {
      const centre = s.room.map((l) => l / 2);
      centre[w.axis] = w.side < 0 ? -thickness / 2 : s.room[w.axis] + thickness / 2;
      const size = s.room.map((l) => l + 2 * thickness);
      size[w.axis] = thickness;
      body.addShape(new Box(new Vec3(size[0] / 2, size[1] / 2, size[2] / 2)));
      body.position.set(...centre);
    }
    world.addBody(body);
    wallBodies.push(body);
  }

  // ---- The ball ----
  const mass = density * (4 / 3) * Math.PI * s.radius ** 3;
  const ball = new Body({
    mass, shape: new Sphere(s.radius), position: new Vec3(...s.position), velocity: new Vec3(...s.velocity),
    linearDamping, angularDamping, allowSleep, fixedRotation: locked,
  });
  if (inertia === 'sphere' && !locked) {
    // Body.updateMassProperties (3852-3863) takes the inertia of the body's
    // bounding box, (2/3) m r^2 for a ball; the sphere's own is 2/5 m r^2.
    ball.shapes[0].calculateLocalInertia(mass, ball.inertia);
    ball.invInertia.set(1 / ball.inertia.x, 1 / ball.inertia.y, 1 / ball.inertia.z);
    ball.updateInertiaWorld(true);
  }
  world.addBody(ball);
  const v = ball.velocity, p = ball.position;

  // ---- Per-contact mode: the ball's `collide` event ----
  if (perContact) {
    // `collide` fires once per new pair of bodies (the pair was not in
    // contact last step, World.internalStep 12704-12712), after the narrow
    // phase and before the solve: the velocity is the step's start velocity.
    // If the ball moves into that wall, the components off its normal are
    // scaled by beta there, once; the solve then bounces the normal one in
    // the same step.
    const scaleOff = (axis) => {
      for (let i = 0; i < 3; ++i) if (i !== axis) {
        if (i === 0) v.x *= s.beta; else if (i === 1) v.y *= s.beta; else v.z *= s.beta;
      }
    };
    ball.addEventListener('collide', (event) => {
      const w = wallBodies.indexOf(event.body);
      if (w < 0) return;
      const { axis, side } = walls[w];
      const vn = axis === 0 ? v.x : axis === 1 ? v.y : v.z;
      if (movesIntoWall(vn, s.gravity[axis], side)) scaleOff(axis);
    });
  }

  // ---- Settings (each why: what cannon's own value did, measured; docs/engines.md, cannon) ----
  const add = (key, value, why) => settings.add(key, value, why);
  const mark = (value, key) => (value === CANNON[key] ? ' [cannon\'s default]' : '');
  add('tangential_model', perContact ? `per-contact: beta = ${s.beta} once at each contact's start, in the ball's collide event` : `friction: mu = ${mu}, each step's friction impulse bounded by mu m |frictionGravity| (cannon's friction equations)`,
    perContact ? 'collide fires after the narrow phase and before the solve of the step that bounces the ball (World.internalStep 12704-12712)'
      : 'the scenario\'s [engines.<name>] friction; cannon bounds each friction impulse by mu |G| m_reduced (createFrictionEquationsFromContact 10459-10473), not by mu times the normal impulse (see friction_gravity)');
  add('restitution', restitution, 'the world\'s default ContactMaterial carries it (no body has a Material, so nothing multiplies it); cannon\'s default 0: no bounce (seed-3d per-contact at 1e-3: highest 6-11 s 0.0500 m against 0.4586)');
  add('contact_relaxation', relaxation, 'SPOOK: b = 4d/(1+4d) multiplies (1 + e) u0 and a = 4/(h(1+4d)) pushes the overlap out in the bounce step (ContactEquation.computeB 6032-6035, setSpookParams 5817-5824): e_eff = (1+e) b - 1 + 4 (1-b) phi, phi the overlap over a step\'s travel. Cannon\'s 3 gives 0.66-0.97 (measured worst 0.969 on every bar scenario; seed-3d highest 6-11 s 0.5505 m against 0.4586); 1000 gives 0.7996-0.8006' + mark(relaxation, 'contact_relaxation'));
  add('contact_stiffness', stiffness, 'SPOOK eps = 4/(h^2 k (1+4d)) softens the impulse by 1/(1 + eps m) (Equation.setSpookParams 5817-5824); 1e7 with 1000 kg/m^3: seed-3d highest 6-11 s 0.4585 m (0.4586), but the 20 m room\'s 4.2 t ball gets e 0.0 (1e9: 0.727, eps m = 0.042)' + mark(stiffness, 'contact_stiffness'));
  add('friction_stiffness', frictionStiffness, 'the friction equations\' softness; kept: 1e12 gives seed-3d in friction mode and a rolling ball the same figures' + mark(frictionStiffness, 'friction_stiffness'));
  add('friction_relaxation', frictionRelaxation, 'kept' + mark(frictionRelaxation, 'friction_relaxation'));
  add('iterations', iterations, 'one contact at a time: one iteration solves it exactly; kept: 1 gives the same bounces to 1e-12 at seed scale' + mark(iterations, 'iterations'));
  add('tolerance', tolerance, 'kept' + mark(tolerance, 'tolerance'));
  add('linear_damping', linearDamping, 'v *= (1 - d)^dt after the solve (World.internalStep 12812-12826); cannon\'s 0.01: seed-3d per-contact at 1e-3, highest 6-11 s 0.4394 m against 0.4586' + mark(linearDamping, 'linear_damping'));
  add('angular_damping', angularDamping, 'as linear_damping, on the spin: a 0.1 m ball rolling off at 1 m/s on mu 0.5 ends at 0.7041 m/s after 5 s against 0.7143' + mark(angularDamping, 'angular_damping'));
  add('allow_sleep', allowSleep, 'the world\'s sleep switch; cannon\'s default is off (World 12184); on, a ball sliding at 0.02 m/s (below the ball\'s 0.1 m/s sleepSpeedLimit) stops' + mark(allowSleep, 'allow_sleep'));
  add('quat_normalize_fast', quatNormalizeFast, 'the orientation does not enter a sphere\'s contact' + mark(quatNormalizeFast, 'quat_normalize_fast'));
  add('walls', wallShape === 'plane' ? 'six static Planes' : `six static boxes ${thickness} m thick, inner faces on the walls`, 'boxes give the same bounces at seed scale (sphereBox) and cost 3-5 times as much' + mark(wallShape, 'walls'));
  add('inertia', inertia === 'sphere' ? '2/5 m r^2 (a solid sphere)' : '2/3 m r^2 (cannon\'s bounding box)', 'cannon\'s box inertia makes a ball rolling off a slide end at 0.6 v0 instead of 5/7 v0' + mark(inertia, 'inertia'));
  add('friction_gravity', frictionGravity === 'gravity-dt' ? `g dt = ${Math.hypot(...s.gravity) * s.dt} m/s (World frictionGravity)` : 'the world\'s gravity (cannon\'s)', 'cannon bounds a friction impulse by mu |g| m (10459-10473), a force used as an impulse: a ball sliding at 1 m/s with mu 0.01 (rotation locked) stops within 10 steps at dt 1e-3 (Coulomb: 0.706 m/s after 3 s); g dt makes the bound Coulomb\'s for a resting ball; impacts still get only mu m |g| dt, not mu times the normal impulse' + mark(frictionGravity, 'friction_gravity'));
  add('density', density, `ball mass ${mass} kg`);
  add('ccd', 'none (contacts only once touching)', 'the ball overlaps a wall for one step at each impact, by up to its speed times dt');
  add('stepping', 'world.step(dt): one fixed internal step, no accumulator, no interpolation', 'World.step 12508-12516 with one argument');
  add('rotation', locked ? 'locked (fixedRotation)' : 'free', 'scenario [engines.<name>] rotation');
  add('gravity', `(${s.gravity.join(', ')}) m/s^2`, 'the scenario\'s');

  const dt = s.dt;
  return {
    step() { world.step(dt); },
    read(out) {
      out[0] = p.x; out[1] = p.y; out[2] = p.z;
      out[3] = v.x; out[4] = v.y; out[5] = v.z;
    },
    free() { while (world.bodies.length) world.removeBody(world.bodies[world.bodies.length - 1]); },
  };
}

export const adapter = {
  name: 'cannon',
  dimensions: [3],
  precision: 'f64',
  packages: () => ['cannon-es'],
  ownKeys,
  // dist/cannon-es.cjs.js (the package's "main"): the ESM build sits in a
  // package that does not declare itself a module, which Node 18 refuses.
  async load() { return createRequire(import.meta.url)('cannon-es'); },
  version: () => '',
  build,
};

await serve(adapter);
