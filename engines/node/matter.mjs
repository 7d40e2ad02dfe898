// matter-js (npm matter-js 0.20.0, Liam Brummitt's 2D engine; plain
// JavaScript, so 64-bit floats) as a bouncecheck simulator: `matter`, 2D only.
// The protocol and the stepping loop are host/protocol.mjs's; this file builds
// the world. Every setting that changes the answer is one of the
// [engines.matter] keys below, defaulting to the value chosen here; each `why`
// says what matter's own default does, measured (docs/engines.md, matter).
// Line numbers are of node_modules/matter-js/build/matter.js.
//
// matter's units are a game's: time in milliseconds, and velocities as the
// displacement per step. Engine.update(engine, delta) (6454-6589) takes delta
// in ms; it adds gravity as a force, mass x gravity x gravity.scale
// (_bodiesApplyGravity, 6654-6671), then Body.update (2330-2376) integrates
// it as Verlet in velocity form: the step's displacement is the last step's
// times (1 - frictionAir delta / (1000/60)), plus force / mass x delta^2. So
// gravity (gx, gy) with scale 1e-6 moves the displacement by g (1000 dt)^2
// 1e-6 = g dt^2 a step: with the world in units_per_metre U and g scaled by U,
// that is exactly semi-implicit Euler in seconds. body.velocity is rescaled to
// units per 1000/60 ms after the step (updateVelocities, 2384-2395); this file
// reads and writes position - positionPrev instead (the displacement, which
// the solvers edit, 7079-7135 and 7241-7314), divided by dt and U.
//
// After the integration, the collision detection (SAT on polygons: a circle is
// a polygon) finds the pairs that overlap, with no speculative margin;
// Pairs.update (7370-7450) lists a pair new this step in collisionStart, and
// the engine fires `collisionStart` (6531) before the position solve (6539-6544)
// and the velocity solve (6556-6559), in the same step. A contact approaching
// faster than Resolver._restingThresh (units per 1000/60 ms, 2 by default:
// 0.12 m/s in millimetres) gets the impulse (1 + e) v_n (7275-7281); slower
// ones are solved as resting contacts whose accumulated impulse only pushes,
// which leaves almost no bounce. The position solve pushes the ball out to an
// overlap of `slop` x min(delta / (1000/60), 1) (7054).
//
// The ball: Bodies.circle makes a regular polygon of ceil(max(10, min(25, r)))
// sides (r in units, made even, 5311-5324), vertices at r, rounded to 0.001
// units (Bodies.polygon, 5350-5358: toFixed(3)). So this file builds the
// polygon itself (Body.create with full-precision vertices), of circle_sides
// sides (a multiple of 4, so a face, not a vertex, meets each of the four
// walls), its vertices at r / cos(pi / sides) so each face lies at r from the
// centre (circle_fit = "faces").
//
// Per-contact mode: matter's `collisionStart` event, on a ball-wall pair, while
// the ball moves into that wall: the displacement along the wall is scaled by
// beta there, once, before the solve that bounces the ball in the same step.

import { serve, ScenarioError, roomWalls, movesIntoWall, ownKey, count1, nonNegative, positive, oneOf, anIntegerAtLeast, trueOrFalse } from './host/protocol.mjs';
import { createRequire } from 'node:module';

const require = createRequire(import.meta.url);

const ownKeys = {
  units_per_metre: 'the world\'s length unit: matter units per metre; positions, sizes, speeds and gravity are scaled by it, time is in ms (default 1000, millimetres; matter\'s numbers assume pixels)',
  circle_sides: 'the ball polygon\'s number of sides; a multiple of 4 puts a face towards every wall (default 128; matter\'s Bodies.circle: ceil(max(10, min(25, r in units))), made even)',
  circle_fit: '"faces": the polygon\'s faces at r from the centre (vertices at r / cos(pi / sides)); "vertices": its vertices at r, matter\'s (default "faces")',
  resting_thresh: 'Resolver._restingThresh as a speed in m/s: slower contacts are solved as resting, without a bounce (default 10 |g| dt; matter\'s 2 units per 1000/60 ms, 0.12 m/s in mm)',
  resting_thresh_tangent: 'Resolver._restingThreshTangent, units per step (default sqrt(6), matter\'s)',
  position_dampen: 'Resolver._positionDampen (default 0.9, matter\'s)',
  position_warming: 'Resolver._positionWarming (default 0.8, matter\'s)',
  slop: 'the ball\'s slop in m: the overlap the position solve leaves, times min(dt / (1000/60 ms), 1) (default 5e-5, matter\'s 0.05 units in mm)',
  friction_air: 'the ball\'s frictionAir: the velocity is scaled by 1 - friction_air x dt / (1000/60 ms) each step (default 0; matter\'s 0.01)',
  friction_static: 'the ball\'s and walls\' frictionStatic, friction mode (default 0.5, matter\'s)',
  position_iterations: 'Engine positionIterations (default 6, matter\'s)',
  velocity_iterations: 'Engine velocityIterations (default 4, matter\'s)',
  sleeping: 'Engine enableSleeping (default false, matter\'s)',
};

function fail(message) { throw new ScenarioError(message); }

const BASE_DELTA = 1000 / 60;  // Common._baseDelta, Body._baseDelta (140, 1611)

const adapter = {
  name: 'matter',
  dimensions: [2],
  precision: 'f64',
  packages: () => ['matter-js'],
  ownKeys,

  async load() { return require('matter-js'); },

  version: (Matter) => `matter-js ${Matter.version}`,

  build(Matter, s, settings) {
    const { Engine, Body, Composite, Events, Resolver } = Matter;
    const e = s.engine;
    const perContact = e.tangential_model === 'per-contact';
    const mu = perContact ? 0 : e.friction;
    if (e.ccd) fail('[engines.matter] matter has no continuous collision (ccd = true is not available)');

    const U = ownKey(s, 'units_per_metre', 1000, positive);
    const sides = ownKey(s, 'circle_sides', 128, anIntegerAtLeast(4));
    const fit = ownKey(s, 'circle_fit', 'faces', oneOf('faces', 'vertices'));
    const g = Math.hypot(...s.gravity);
    const restingSpeed = ownKey(s, 'resting_thresh', 10 * g * s.dt, nonNegative);
    const restingTangent = ownKey(s, 'resting_thresh_tangent', Math.sqrt(6), nonNegative);
    const positionDampen = ownKey(s, 'position_dampen', 0.9, nonNegative);
    const positionWarming = ownKey(s, 'position_warming', 0.8, nonNegative);
    const slop = ownKey(s, 'slop', 0.05 / 1000, nonNegative);
    const frictionAir = ownKey(s, 'friction_air', 0, nonNegative);
    const frictionStatic = ownKey(s, 'friction_static', 0.5, nonNegative);
    const positionIterations = ownKey(s, 'position_iterations', 6, count1);
    const velocityIterations = ownKey(s, 'velocity_iterations', 4, count1);
    const sleeping = ownKey(s, 'sleeping', false, trueOrFalse);

    const dtMs = s.dt * 1000;
    // Resolver's numbers are module statics read live by the solver
    // (6975-6978): every build sets them all (one world at a time per process).
    Resolver._restingThresh = restingSpeed * U * BASE_DELTA / 1000;
    Resolver._restingThreshTangent = restingTangent;
    Resolver._positionDampen = positionDampen;
    Resolver._positionWarming = positionWarming;
    // Engine.update warns once when delta > 1000/60 ms (6465); dt 0.03 is
    // 30 ms, which matter handles (its thresholds scale with delta).
    Engine._deltaMax = Math.max(Engine._deltaMax, dtMs);

    const engine = Engine.create({
      gravity: { x: s.gravity[0] * U, y: s.gravity[1] * U, scale: 1e-6 },
      positionIterations, velocityIterations, constraintIterations: 2, enableSleeping: sleeping,
    });

    // The walls: a static box per wall, outside the room with its inner face
    // on the wall, as thick as the room is large, overlapping at the corners.
    const walls = roomWalls(s);
    const thick = Math.max(...s.room) * U;
    const wallOf = new Map();  // body -> index in `walls`
    const rect = (w, h) => [{ x: -w / 2, y: -h / 2 }, { x: w / 2, y: -h / 2 }, { x: w / 2, y: h / 2 }, { x: -w / 2, y: h / 2 }];
    walls.forEach((w, index) => {
      const size = [s.room[0] * U + 2 * thick, s.room[1] * U + 2 * thick];
      size[w.axis] = thick;
      const centre = [s.room[0] * U / 2, s.room[1] * U / 2];
      centre[w.axis] = w.offset * U + w.side * thick / 2;
      const body = Body.create({
        isStatic: true, position: { x: centre[0], y: centre[1] }, vertices: rect(size[0], size[1]),
        restitution: s.alpha, friction: mu, frictionStatic, slop: 0,
      });
      Composite.add(engine.world, body);
      wallOf.set(body, index);
    });

    // The ball: a regular polygon of `sides` sides, built with full-precision
    // vertices (Bodies.polygon rounds them to 0.001 units), a face towards
    // each wall at angle 0 (sides a multiple of 4, offset half a side).
    const r = s.radius * U;
    const R = fit === 'faces' ? r / Math.cos(Math.PI / sides) : r;
    const theta = 2 * Math.PI / sides;
    const offset = fit === 'faces' ? theta / 2 : 0;
    const vertices = [];
    for (let i = 0; i < sides; ++i) {
      const a = offset + i * theta;
      vertices.push({ x: R * Math.cos(a), y: R * Math.sin(a) });
    }
    const ball = Body.create({
      label: 'Circle Body', circleRadius: r,
      position: { x: s.position[0] * U, y: s.position[1] * U }, vertices,
      restitution: s.alpha, friction: mu, frictionStatic, frictionAir, slop: slop * U,
    });
    if (e.rotation === 'locked') Body.setInertia(ball, Infinity);
    // The start velocity as this step's displacement; deltaTime = dt so the
    // first step's time correction (2334) is 1.
    ball.deltaTime = dtMs;
    ball.positionPrev.x = ball.position.x - s.velocity[0] * U * s.dt;
    ball.positionPrev.y = ball.position.y - s.velocity[1] * U * s.dt;
    ball.velocity.x = s.velocity[0] * U * s.dt;
    ball.velocity.y = s.velocity[1] * U * s.dt;
    Composite.add(engine.world, ball);

    const add = (key, value, why) => settings.add(key, value, why);
    add('units_per_metre', U, 'matter\'s numbers assume pixel-like units: the resting threshold 2 units per 1000/60 ms, slop 0.05 units, the 0.001-unit vertex rounding of Bodies.polygon, at most r-in-units circle sides, and its friction (a fixed number of units a step, 7253-7262). resting_thresh and slop are keys in metres here, so per-contact mode is the same in metres (1): seed-2d at dt 1e-3 identical rows; friction mode is not: mu 0.0035 in metres, highest from 5 to 10.5 s 0.6148 m against 0.6252 in mm. With every matter default in metres (threshold 120 m/s, slop 0.05 m, 10 sides, frictionAir 0.01) the seed never bounces again after 7.16 s and rests 5.5 mm inside the floor');
    add('gravity', `(${s.gravity.join(', ')}) m/s^2`, 'engine.gravity = the scenario\'s x units_per_metre with scale 1e-6: g (1000 dt)^2 1e-6 U = g U dt^2 a step, exact (6654-6671, 2342-2343)');
    add('time_step', `${dtMs} ms`, 'Engine.update(engine, dt in ms); timing.timeScale 1, body timeScale 1; Body._timeCorrection kept (constant delta: factor 1)');
    add('circle_sides', sides, `the ball polygon (matter's Bodies.circle would give ${Math.ceil(Math.max(10, Math.min(25, r))) + (Math.ceil(Math.max(10, Math.min(25, r))) % 2)} here). A face contact's two points are r tan(pi / sides) off the normal line and the solver's effective mass counts their lever arms (7270-7275): with free rotation the bounce is (1 + alpha) / (1 + m d^2 / I) - 1, m d^2 / I = tan^2(pi / sides) / 2 (matter's inertia is 4 x the polygon's, Body._inertiaScale, 1607): 64 sides lose 0.27% of e per bounce (seed-2d at dt 1e-3, apex 3 1.63% low), 128 sides 0.07% (0.49%), 256 sides 0.02% (0.17%) at 3 times the cost. matter's 26 sides with vertices at r: highest from 5 to 10.5 s 0.5999 m against 0.6177, the ball 0.37 mm inside the side walls (faces at r cos(pi / 26))`);
    add('circle_fit', fit, fit === 'faces' ? 'vertices at r / cos(pi / sides), the first at half a side: with sides a multiple of 4 a face meets each wall at r from the centre (matter\'s vertices at r: at 128 sides the ball reaches 0.018 mm inside the side walls, the same apexes)' : 'vertices at r (matter\'s): faces at r cos(pi / sides), vertices at r');
    add('resting_thresh', restingSpeed, `m/s; Resolver._restingThresh = ${Resolver._restingThresh} units per 1000/60 ms (7190, 7275-7291). matter's default 2 (0.12 m/s in mm): slower impacts are solved as resting contacts, whose accumulated impulse only pushes, and barely bounce; seed-2d at dt 1e-3 then ends sliding at 0.0085 m/s instead of 0.0502 (the low hops end sooner)`);
    add('resting_thresh_tangent', restingTangent, 'Resolver._restingThreshTangent, matter\'s');
    add('position_solver', `dampen ${positionDampen}, warming ${positionWarming}, ${positionIterations} iterations`, 'Resolver._positionDampen and _positionWarming, Engine positionIterations: matter\'s (1 position and 1 velocity iteration: the same apexes to 1e-5 m, 0.033 mm deep instead of 0.003)');
    add('velocity_iterations', velocityIterations, 'Engine velocityIterations, matter\'s');
    add('slop', slop, 'm, on the ball (walls 0; pairs take the larger, 4545): the position solve leaves this x min(dt / (1000/60 ms), 1) of overlap (7054); matter\'s 0.05 units in mm (0: 0.8 um deep instead of 3 um, the same apexes)');
    add('friction_air', frictionAir, 'the ball\'s frictionAir (matter\'s default 0.01 scales the displacement by 1 - 0.01 dt / (1000/60 ms) each step (2337), 0.6 per second: seed-2d at dt 1e-3 first lands at 7.16 s instead of 4.293 s, highest from 5 to 10.5 s 0.3925 m against 0.6177)');
    add('restitution', s.alpha, 'alpha on the ball and the walls; a pair takes the larger (4544)');
    add('friction', mu, perContact ? 'per-contact mode: 0 on the ball and walls (a pair takes the smaller)' : 'matter\'s friction = mu on ball and walls (a pair takes the smaller): not Coulomb. A sliding contact loses a fixed friction x (dt / (1000/60 ms))^3 units of displacement per velocity iteration (7253-7262), whatever the normal force, once the contact overlaps');
    add('friction_static', frictionStatic, 'frictionStatic, matter\'s: sticks when |v_t| < overlap x friction x frictionStatic x 5 dt / (1000/60 ms) (7214, 7250-7264)');
    add('sleeping', sleeping, 'Engine enableSleeping, matter\'s default (on: the same seed-2d rows at dt 1e-3, the sliding ball never rests)');
    add('rotation', e.rotation, e.rotation === 'locked' ? 'Body.setInertia(ball, Infinity)' : 'the ball spins freely (inertia 4 x the polygon\'s, Body._inertiaScale)');
    add('ccd', false, 'matter has no continuous collision');
    add('walls', 'a static box per wall, inner face on the wall', 'as thick as the room is large, overlapping at the corners');
    add('per_contact', perContact ? 'collisionStart, displacement along the wall scaled there' : 'off',
      perContact ? 'matter\'s collisionStart fires after detection and before the position and velocity solves of the same step (6531-6557); the displacement along the wall is scaled by beta there, once per contact, if the ball moves into the wall' : 'friction mode');

    // A wall counts a new contact only once the ball has left it faster than
    // a step of gravity (`away`), as planck: a resting ball's contact may end
    // and start again.
    const away = new Array(walls.length).fill(true);
    const eps = g * s.dt * U * s.dt;  // a step of gravity, as displacement
    if (perContact) {
      Events.on(engine, 'collisionStart', (event) => {
        for (const pair of event.pairs) {
          const a = pair.bodyA, b = pair.bodyB;
          const w = wallOf.has(a) ? wallOf.get(a) : wallOf.get(b);
          if (w === undefined || !away[w]) continue;
          const { axis, side } = walls[w];
          const d = [ball.position.x - ball.positionPrev.x, ball.position.y - ball.positionPrev.y];
          if (!movesIntoWall(d[axis], s.gravity[axis], side)) continue;
          away[w] = false;
          if (axis !== 0) ball.positionPrev.x = ball.position.x - d[0] * s.beta;
          if (axis !== 1) ball.positionPrev.y = ball.position.y - d[1] * s.beta;
        }
      });
    }
    const per = 1 / (U * s.dt);
    return {
      step: perContact
        ? () => {
          Engine.update(engine, dtMs);
          const dx = ball.position.x - ball.positionPrev.x, dy = ball.position.y - ball.positionPrev.y;
          for (let w = 0; w < walls.length; ++w)
            if ((walls[w].axis === 0 ? dx : dy) * walls[w].side < -eps) away[w] = true;
        }
        : () => Engine.update(engine, dtMs),
      read(out) {
        out[0] = ball.position.x / U; out[1] = ball.position.y / U;
        out[2] = (ball.position.x - ball.positionPrev.x) * per; out[3] = (ball.position.y - ball.positionPrev.y) * per;
      },
      free() { Composite.clear(engine.world, false); Engine.clear(engine); },
    };
  },
};

await serve(adapter);
