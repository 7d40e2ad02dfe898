// p2 (npm p2-es 1.2.3: the pmndrs fork of Stefan Hedman's p2.js, plain
// JavaScript, so 64-bit floats) as a bouncecheck simulator: `p2`, 2D only. The
// protocol and the stepping loop are host/protocol.mjs's; this file builds the
// world. Every setting that changes the answer is one of the [engines.p2] keys
// below, defaulting to the value chosen here; each `why` says what p2's own
// default does, measured (docs/engines.md, p2). Line numbers are of
// node_modules/p2-es/dist/p2-es.js.
//
// How a p2 step goes (World.internalStep, 9669-9958): gravity is added as a
// force, damping scales the velocity by (1 - damping)^dt (Body.applyDamping,
// 3320), the narrowphase makes a contact equation for every shape pair that
// overlaps (circle-plane: only once the ball's centre is within r of the plane,
// no speculative margin, 5820-5871), and emits beginContact for a pair that did
// not overlap in the step before (10379-10395). Then the Gauss-Seidel solver
// (GSSolver.solve, 8972) solves SPOOK equations: a contact is a spring of
// `stiffness` with `relaxation` steps of damping (Equation.update, 4075:
// epsilon = 4 / (h^2 k (1 + 4 d))); it drives the gap to -contactSkinSize
// (ContactEquation.computeB, 4269-4305: Gq = gap + offset). Restitution acts
// only in the step the bodies first touch (firstImpact, 4293-4295: the target
// normal velocity is -(1 + e) times the approach speed, softened by epsilon),
// and the bodies then integrate (semi-implicit Euler, Body.integrate).
//
// Per-contact mode: the beginContact event names the wall the ball starts
// touching, inside the step before the solve; if the ball moves into that
// wall then (host/protocol.mjs movesIntoWall), the preSolve event (9812)
// scales every velocity component normal to none of the starting walls by
// beta, once, in the step the engine bounces the ball. Friction is 0, so the
// solver touches only the normal component.

import { serve, ScenarioError, roomWalls, movesIntoWall, ownKey, count0, count1, nonNegative, positive, trueOrFalse } from './host/protocol.mjs';

const ownKeys = {
  stiffness: 'ContactMaterial.stiffness of the ball-wall contact (default 1e12; p2 default 1e6, which softens the bounce)',
  relaxation: 'ContactMaterial.relaxation, in steps (default 4, p2\'s)',
  contact_skin_size: 'ContactMaterial.contactSkinSize in m: how deep a touching ball is held inside the wall (default 1e-6; p2 default 0.005)',
  friction_stiffness: 'ContactMaterial.frictionStiffness (default 1e12; p2 default 1e6)',
  friction_relaxation: 'ContactMaterial.frictionRelaxation, in steps (default 4, p2\'s)',
  friction_iterations: 'GSSolver.frictionIterations: > 0 bounds friction by mu x the solved normal force (default 10; p2 default 0: by mu m |g|)',
  solver_iterations: 'GSSolver.iterations (default 10, p2\'s)',
  solver_tolerance: 'GSSolver.tolerance (default 1e-7, p2\'s)',
  damping: 'the ball\'s linear damping, fraction of velocity lost per second (default 0; p2 default 0.1)',
  angular_damping: 'the ball\'s angular damping (default 0; p2 default 0.1)',
  sleeping: 'World.sleepMode BODY_SLEEPING and the ball\'s allowSleep (default false; p2 default NO_SLEEPING, the same)',
  island_split: 'World.islandSplit (default true, p2\'s)',
};

function fail(message) { throw new ScenarioError(message); }

// The angle of a Plane whose normal (p2 rotates +y by the angle) points into
// the room from wall `w`.
function planeAngle(w) {
  if (w.axis === 1) return w.side < 0 ? 0 : Math.PI;
  return w.side < 0 ? -Math.PI / 2 : Math.PI / 2;
}

const adapter = {
  name: 'p2',
  dimensions: [2],
  precision: 'f64',
  packages: () => ['p2-es'],
  ownKeys,

  async load() {
    return import('p2-es');
  },

  version: () => '',

  build(p2, s, settings) {
    const e = s.engine;
    const perContact = e.tangential_model === 'per-contact';
    if (e.tangential_model !== 'friction' && !perContact) fail('[engines.p2] tangential_model must be "friction" or "per-contact"');
    if (perContact && e.friction !== 0) fail('[engines.p2] per-contact mode runs with friction 0');
    const mu = perContact ? 0 : e.friction;
    const ccd = e.ccd === undefined ? false : e.ccd;
    if (typeof ccd !== 'boolean') fail('[engines.p2] ccd must be true or false');

    const stiffness = ownKey(s, 'stiffness', 1e12, positive);
    const relaxation = ownKey(s, 'relaxation', 4, nonNegative);
    const skin = ownKey(s, 'contact_skin_size', 1e-6, nonNegative);
    const frictionStiffness = ownKey(s, 'friction_stiffness', 1e12, positive);
    const frictionRelaxation = ownKey(s, 'friction_relaxation', 4, nonNegative);
    const frictionIterations = ownKey(s, 'friction_iterations', 10, count0);
    const iterations = ownKey(s, 'solver_iterations', 10, count1);
    const tolerance = ownKey(s, 'solver_tolerance', 1e-7, nonNegative);
    const damping = ownKey(s, 'damping', 0, nonNegative);
    const angularDamping = ownKey(s, 'angular_damping', 0, nonNegative);
    const sleeping = ownKey(s, 'sleeping', false, trueOrFalse);
    const islandSplit = ownKey(s, 'island_split', true, trueOrFalse);
    if (damping > 1 || angularDamping > 1) fail('[engines.p2] damping and angular_damping must be at most 1');

    const world = new p2.World({ gravity: [s.gravity[0], s.gravity[1]], islandSplit });
    world.sleepMode = sleeping ? p2.World.BODY_SLEEPING : p2.World.NO_SLEEPING;
    world.solver.iterations = iterations;
    world.solver.tolerance = tolerance;
    world.solver.frictionIterations = frictionIterations;
    // Every shape keeps the world's default material, so every contact uses
    // the world's default contact material: set it.
    const cm = world.defaultContactMaterial;
    cm.friction = mu;
    cm.restitution = s.alpha;
    cm.stiffness = stiffness;
    cm.relaxation = relaxation;
    cm.frictionStiffness = frictionStiffness;
    cm.frictionRelaxation = frictionRelaxation;
    cm.contactSkinSize = skin;
    cm.surfaceVelocity = 0;

    // The walls: one static body per wall (p2's firstImpact, which carries the
    // restitution, is kept per pair of bodies, 4676), each a Plane through the
    // wall, its normal into the room.
    const walls = roomWalls(s);
    const wallOf = new Map();  // body -> index in `walls`
    walls.forEach((w, index) => {
      const at = [0, 0];
      at[w.axis] = w.offset;
      const body = new p2.Body({ mass: 0, position: at, angle: planeAngle(w) });
      body.addShape(new p2.Plane());
      world.addBody(body);
      wallOf.set(body, index);
    });

    // The ball: density 1 kg/m^2 (as Box2D's default), so its mass is pi r^2.
    const mass = Math.PI * s.radius * s.radius;
    const ball = new p2.Body({
      mass,
      position: [s.position[0], s.position[1]],
      velocity: [s.velocity[0], s.velocity[1]],
      damping,
      angularDamping,
      fixedRotation: e.rotation === 'locked',
      allowSleep: sleeping,
      ccdSpeedThreshold: ccd ? 0 : -1,
    });
    ball.addShape(new p2.Circle({ radius: s.radius }));
    world.addBody(ball);

    const add = (key, value, why) => settings.add(key, value, why);
    add('gravity', `(${s.gravity.join(', ')})`, 'the scenario\'s, in the World (p2\'s default (0, -9.78)); gravity scale 1');
    add('mass', mass, 'the ball\'s: density 1 kg/m^2 x pi r^2 (as Box2D). The contact\'s softness epsilon is relative to 1/m: a heavier ball needs a stiffer contact');
    add('restitution', s.alpha, 'alpha, on the world\'s default contact material, used by every contact (ContactMaterial default 0); p2 applies it in the first step of a contact only');
    add('stiffness', stiffness, 'ContactMaterial.stiffness. The bounce is (1 + alpha) / (1 + epsilon m) - 1, epsilon = 4 / (dt^2 k (1 + 4 relaxation)). p2\'s default 1e6 at dt 1e-3: a 20 m room with a 1 m ball (m 3.14 kg) bounces at e 0.035, first apex 1.127 m against 12.374; seed-2d (m 0.0079 kg) at e 0.797, first apex after the start 0.6141 m against 0.6187. At 1e12, epsilon m is under 1e-6 on both');
    add('relaxation', relaxation, 'ContactMaterial.relaxation, p2\'s default, kept (1: seed-2d at dt 0.03 ends sliding at 0.016 m/s instead of 0.050, from more re-contacts while settling; 16 at dt 1e-3: the same rows)');
    add('contact_skin_size', skin, 'ContactMaterial.contactSkinSize: the solver holds a touching ball this far inside the wall (4269-4305). p2\'s default 0.005: seed-2d at dt 1e-3 rests 5.000 mm beyond the floor (bar: 2 mm), the 0.2 m room too; the bounces are the same. 1 um: rests at r. 0: also at r, one more re-contact while settling (final vx 0.04209 against 0.04251)');
    add('friction', mu, perContact ? 'per-contact mode: 0 on the default contact material (no friction equations, 10340)' : 'Coulomb mu from [engines] friction, on the default contact material');
    add('friction_stiffness', frictionStiffness, 'ContactMaterial.frictionStiffness, as stiffness (p2\'s default 1e6: seed-2d friction mode identical to 8 digits; a 20 m room with mu 0.01, third apex 2.120% from exact against 2.127%)');
    add('friction_relaxation', frictionRelaxation, 'ContactMaterial.frictionRelaxation, p2\'s default, kept');
    add('friction_iterations', frictionIterations, 'GSSolver.frictionIterations: Coulomb friction, bounded by mu x the normal force the solver found (9010-9041). p2\'s default 0 bounds it by mu m |g| (10340-10349), so an impact gets almost none: seed-2d friction mode (mu 0.0035505, dt 1e-3) first apex after the start 0.6259 m against 0.6205');
    add('solver', `GSSolver, ${iterations} iterations, tolerance ${tolerance}`, 'p2\'s defaults, kept (1 iteration or tolerance 0: the same rows on seed-2d, one contact at a time)');
    add('damping', `linear ${damping}, angular ${angularDamping}`, 'the ball\'s, v x (1 - damping)^dt per step (3320). p2\'s default 0.1 each: seed-2d at dt 1e-3 first touches the floor at 4.642 s instead of 4.293, first apex after the start 0.4001 m against 0.6187; angular 0.1 changes friction mode\'s final speed by 2e-6 (the ball always slides)');
    add('sleeping', sleeping, 'World.sleepMode and the ball\'s allowSleep (p2\'s default NO_SLEEPING, the same. BODY_SLEEPING: under sleepSpeedLimit 0.2 m/s for 1 s, seed-2d\'s ball freezes mid-air at 8.057 s, 0.612 m up)');
    add('island_split', islandSplit, 'World.islandSplit, p2\'s default (false: the same rows on seed-2d)');
    add('ccd', ccd, ccd ? 'ccdSpeedThreshold 0: a ray from the ball\'s centre stops the ball at the first body it crosses' : 'p2\'s default (ccdSpeedThreshold -1): off. Its CCD casts the centre\'s ray (3461-3556), so it catches only a ball about to pass r deep; on, seed-2d\'s rows are the same at dt 1e-3 and 0.03');
    add('rotation', e.rotation, e.rotation === 'locked' ? 'the ball\'s fixedRotation' : 'the ball spins freely');
    add('walls', 'a Plane per wall, each on its own static body', 'restitution\'s firstImpact is tracked per pair of bodies');
    add('per_contact', perContact ? 'beginContact, beta applied in preSolve' : 'off',
      perContact ? 'beginContact (inside the step, before the solve) names the wall; if the ball moves into it, the other component is scaled by beta before the solve, once' : 'friction mode');

    const d = 2;
    const starting = [];
    if (perContact) {
      world.on('beginContact', (ev) => {
        const w = wallOf.get(ev.bodyA === ball ? ev.bodyB : ev.bodyA);
        if (w === undefined) return;
        const { axis, side } = walls[w];
        if (movesIntoWall(ball.velocity[axis], s.gravity[axis], side)) starting.push(axis);
      });
      world.on('preSolve', () => {
        if (!starting.length) return;
        for (let i = 0; i < d; ++i) if (!starting.includes(i)) ball.velocity[i] *= s.beta;
        starting.length = 0;
      });
    }
    const dt = s.dt;
    return {
      step: () => world.step(dt),
      read(out) {
        out[0] = ball.position[0]; out[1] = ball.position[1];
        out[2] = ball.velocity[0]; out[3] = ball.velocity[1];
      },
      free() { world.clear(); },
    };
  },
};

await serve(adapter);
