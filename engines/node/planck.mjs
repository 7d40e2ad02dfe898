// planck.js (npm planck 1.4.2: Ali Shakiba's TypeScript port of Box2D 2.x;
// plain JavaScript, 64-bit floats) as a bouncecheck simulator: `planck`, 2D
// only. The protocol and the stepping loop are host/protocol.mjs's; this file
// builds the world. Every setting that changes the answer is one of the
// [engines.planck] keys below, defaulting to the value chosen here; each `why`
// says what planck's own default does, measured (docs/engines.md, planck).
//
// How a planck step goes (src/dynamics/World.ts:804-870, Contact.ts,
// Solver.ts in the package): updateContacts() first re-collides every contact
// from the positions the step starts with; a circle-polygon contact touches
// when its manifold has a point, i.e. when the ball overlaps the polygon
// grown by its skin (Settings.polygonRadius = 2 x linearSlop, 1 cm;
// PolygonShape.ts:65, Settings.ts:69). A contact that starts touching fires
// "begin-contact" there (Contact.ts:597). Then solveWorld copies the body's
// velocity (Solver.ts:296), adds gravity, and solves the contact: a point
// approaching faster than Settings.velocityThreshold (1 m/s) gets the
// restitution bias -e x vRel (Contact.ts:819), from the velocity after
// gravity. Positions are corrected towards an overlap of linearSlop
// (Contact.ts:716). No speculative contact: a ball is only turned once it
// overlaps the skin. Continuous collision (solveWorldTOI) then stops a fast
// ball at 3 x linearSlop inside the combined radius (TimeOfImpact.ts:120),
// updates the contact there (begin-contact again fires, Solver.ts:681) and
// solves it (its velocity copied at Solver.ts:756).
//
// The walls: the skin is moved outside the room. Each wall is a box whose
// core face lies `wall_offset` (by default the skin) outside the room, so the
// skin's face is the wall: the engine touches exactly when the ball overlaps
// the room's wall.
//
// Per-contact mode: planck's own "begin-contact" event, on a ball-wall
// contact, while the ball moves into that wall: the velocity component along
// the wall is scaled by beta there, once, before the solve in which the same
// contact bounces the ball (both solveWorld and the TOI solve read the body's
// velocity after the contact update).

import { World, Vec2, Circle, Box, Settings } from 'planck';
import { serve, ScenarioError, roomWalls, maxBallSpeed, movesIntoWall, ownKey, count1, nonNegative, positive, trueOrFalse } from './host/protocol.mjs';

const ownKeys = {
  velocity_threshold: 'Settings.velocityThreshold in m/s: slower contacts do not bounce (default 10 steps of gravity, 10 |g| dt; planck default 1)',
  wall_offset: 'how far outside the room each wall box\'s core face lies, m (default: the polygon skin, 2 x linear_slop; planck: 0, the box face on the wall)',
  linear_slop: 'Settings.linearSlop, m: the polygon skin is twice it, the allowed overlap once (default 0.005, planck\'s)',
  wall_restitution: 'restitution of the walls (default: alpha, as the ball; planck default 0, combined by max)',
  wall_friction: 'friction of the walls (default: the ball\'s mu; planck default 0.2, combined by sqrt(mu1 mu2))',
  sleeping: 'World allowSleep and the ball\'s allowSleep (default false; planck default true)',
  velocity_iterations: 'World.step velocity iterations (default 8, planck\'s)',
  position_iterations: 'World.step position iterations (default 3, planck\'s)',
  max_translation: 'Settings.maxTranslation, m per step: a faster body is slowed to it (default: 4 x the fastest the ball can move x dt, at least 2; planck default 2)',
  linear_damping: 'the ball\'s linear damping (default 0, planck\'s)',
  angular_damping: 'the ball\'s angular damping (default 0, planck\'s)',
};

function fail(message) { throw new ScenarioError(message); }

const adapter = {
  name: 'planck',
  dimensions: [2],
  precision: 'f64',
  packages: () => ['planck'],
  ownKeys,

  async load() { return { World, Vec2, Circle, Box, Settings }; },

  version: () => 'planck.js 1.4.2 (Box2D 2.x port)',

  build(lib, s, settings) {
    const e = s.engine;
    const perContact = e.tangential_model === 'per-contact';
    if (e.tangential_model !== 'friction' && !perContact) fail('[engines.planck] tangential_model must be "friction" or "per-contact"');
    if (e.rotation !== 'free' && e.rotation !== 'locked') fail('[engines.planck] rotation must be "free" or "locked"');
    if (perContact && e.friction !== 0) fail('[engines.planck] per-contact mode runs with friction 0');
    const mu = perContact ? 0 : e.friction;
    const ccd = e.ccd === undefined ? true : e.ccd;
    if (typeof ccd !== 'boolean') fail('[engines.planck] ccd must be true or false');

    // Ten steps of gravity: at 0 the resting ball is bounced by every step's
    // gravity and starts a new contact every few steps (seed-2d at 1e-3: the
    // ball's 0.047 m/s slide along the floor is eaten by beta by 42 s).
    const threshold = ownKey(s, 'velocity_threshold', 10 * Math.hypot(...s.gravity) * s.dt, nonNegative);
    const slop = ownKey(s, 'linear_slop', 0.005, positive);
    const skin = 2 * slop;
    const wallOffset = ownKey(s, 'wall_offset', skin, nonNegative);
    const wallRestitution = ownKey(s, 'wall_restitution', s.alpha, nonNegative);
    const wallFriction = ownKey(s, 'wall_friction', mu, nonNegative);
    const sleeping = ownKey(s, 'sleeping', false, trueOrFalse);
    const velocityIterations = ownKey(s, 'velocity_iterations', 8, count1);
    const positionIterations = ownKey(s, 'position_iterations', 3, count1);
    const maxTranslation = ownKey(s, 'max_translation', Math.max(2, 4 * maxBallSpeed(s) * s.dt), positive);
    const linearDamping = ownKey(s, 'linear_damping', 0, nonNegative);
    const angularDamping = ownKey(s, 'angular_damping', 0, nonNegative);

    // planck's Settings are global, read live by the solver (SettingsInternal,
    // Settings.ts:150-220) and, for the skin, when a polygon is made: every
    // build sets them all (one world at a time per process).
    const S = lib.Settings;
    S.lengthUnitsPerMeter = 1;
    S.linearSlop = slop;
    S.velocityThreshold = threshold;
    S.maxTranslation = maxTranslation;

    const world = new lib.World({
      gravity: lib.Vec2(s.gravity[0], s.gravity[1]),
      allowSleep: sleeping,
      continuousPhysics: ccd,
      velocityIterations,
      positionIterations,
    });

    // The walls: one static body, a box per wall lying outside the room with
    // its core face wallOffset outside the wall, as thick as the room is large
    // and overlapping at the corners.
    const walls = roomWalls(s);
    const thick = Math.max(...s.room);
    const wallBody = world.createBody({ type: 'static' });
    const wallFixtures = new Map();  // fixture -> index in `walls`
    walls.forEach((w, index) => {
      const half = [s.room[0] / 2 + thick + wallOffset, s.room[1] / 2 + thick + wallOffset];
      half[w.axis] = thick / 2;
      const centre = [s.room[0] / 2, s.room[1] / 2];
      centre[w.axis] = w.offset + w.side * (wallOffset + thick / 2);
      const box = new lib.Box(half[0], half[1], lib.Vec2(centre[0], centre[1]), 0);
      const fixture = wallBody.createFixture({ shape: box, restitution: wallRestitution, friction: wallFriction });
      wallFixtures.set(fixture, index);
    });

    const ball = world.createBody({
      type: 'dynamic',
      position: lib.Vec2(s.position[0], s.position[1]),
      linearVelocity: lib.Vec2(s.velocity[0], s.velocity[1]),
      allowSleep: sleeping,
      linearDamping,
      angularDamping,
      fixedRotation: e.rotation === 'locked',
      bullet: false,
    });
    ball.createFixture({ shape: new lib.Circle(s.radius), density: 1, restitution: s.alpha, friction: mu });

    const add = (key, value, why) => settings.add(key, value, why);
    add('gravity', `(${s.gravity.join(', ')})`, 'the scenario\'s, in the World definition (planck\'s default (0, 0)); gravity scale 1');
    add('velocity_threshold', threshold, 'Settings.velocityThreshold, 10 |g| dt: 0 bounces the resting ball on every step (seed-2d at 1e-3: its slide stops at 42 s, vx 0.00088) (planck\'s default 1 m/s: seed-2d\'s 0.42 m/s floor impact does not bounce, the ball lies on the floor from t = 4.29 s, at dt 1e-3)');
    add('linear_slop', slop, 'Settings.linearSlop, planck\'s 0.005 m kept: the polygon skin is 2 x it (1 cm), position correction leaves an overlap of 1 x it, continuous collision stops 3 x it inside the combined radius (0.001: the same seed-2d figures at 1e-3, the wall offset following it)');
    add('wall_offset', wallOffset, 'the walls\' core faces this far outside the room, so the polygon skin ends on the wall (planck\'s way, faces on the walls: the ball turns and rests 1 cm short of every wall; seed-2d at 1e-3 lies at y = 0.0600 from 45 s instead of 0.0500, and the harness sees no floor contact at all on seed-2d or the 0.2 m room)');
    add('ball_restitution', s.alpha, 'alpha, on the ball\'s fixture');
    add('wall_restitution', wallRestitution, 'on every wall (planck\'s default 0; restitution combines by max (mixRestitution, Contact.ts:91), so alpha either way: seed-2d\'s rows identical)');
    add('restitution_combine', 'max', 'planck\'s mixRestitution, kept (a module function, not settable)');
    add('friction', mu, perContact ? 'per-contact mode: 0 on the ball' : 'Coulomb mu from [engines] friction, on the ball');
    add('wall_friction', wallFriction, 'on every wall, equal to the ball\'s (planck\'s default 0.2, combined by sqrt(mu1 mu2) (mixFriction, Contact.ts:83): friction mode with mu 0.004 gets 0.028, seed-2d at 1e-3 highest between 5 and 10.5 s 0.5858 m instead of 0.6200; in per-contact mode sqrt(0 x 0.2) = 0, no effect)');
    add('friction_combine', 'sqrt(mu1 mu2)', 'planck\'s mixFriction, kept; both fixtures carry mu, so the contact gets mu');
    add('sleeping', sleeping, 'World allowSleep and the ball\'s (planck\'s default true: no effect on seed-2d, whose slide at 0.046 m/s stays above the 0.01 m/s sleep tolerance; started at 0.01 m/s instead of 0.3, the ball ends at 0 instead of 0.0059 m/s)');
    add('iterations', `velocity ${velocityIterations}, position ${positionIterations}`, 'planck\'s defaults (World 8 and 3; 1 and 1 gave the same seed-2d rows at 1e-3, one contact point)');
    add('max_translation', maxTranslation, 'Settings.maxTranslation: the most a body moves in a step, set so that it never binds here (planck\'s 2 m caps the speed at 2 / dt: 66.7 m/s at dt 0.03, 2000 m/s at 1e-3; no effect on seed-2d at 1e-3 or 0.03)');
    add('max_rotation', '0.5 pi per step', 'Settings.maxRotation, planck\'s, kept: caps the spin at pi / (2 dt)');
    add('position_correction', 'baumgarte 0.2, TOI 0.75, at most 0.2 m', 'planck\'s Settings, kept');
    add('damping', `linear ${linearDamping}, angular ${angularDamping}`, 'planck\'s defaults, set explicitly');
    add('ccd', ccd, ccd ? 'World continuousPhysics, planck\'s default: the dynamic ball is swept against the static walls' : 'continuous collision off ([engines] ccd = false)');
    add('rotation', e.rotation, e.rotation === 'locked' ? 'the ball\'s fixedRotation' : 'the ball spins freely');
    add('walls', 'boxes outside the room, skins ending on the walls', 'one static body, a box per wall, as thick as the room is large');
    add('per_contact', perContact ? 'begin-contact event, tangential velocity scaled there' : 'off',
      perContact ? 'planck\'s begin-contact fires in the contact update that precedes the solve that bounces the ball; the velocity along the wall is scaled by beta there, once per contact, if the ball moves into the wall' : 'friction mode');

    // A wall counts a new contact only once the ball has left it faster than
    // a step of gravity (`away`): a ball resting on the floor, which the
    // engine bounces by less than that (velocity_threshold 0), starts a new
    // engine contact every few steps, and each would take beta again (seed-2d:
    // the sliding ball stops at x = 0.4416 by 45 s instead of sliding on).
    const away = new Array(walls.length).fill(true);
    const eps = Math.hypot(...s.gravity) * s.dt;
    if (perContact) {
      world.on('begin-contact', (contact) => {
        const a = contact.getFixtureA(), b = contact.getFixtureB();
        const w = wallFixtures.has(a) ? wallFixtures.get(a) : wallFixtures.get(b);
        if (w === undefined || !away[w]) return;
        const { axis, side } = walls[w];
        const v = ball.getLinearVelocity();
        const now = [v.x, v.y];
        if (!movesIntoWall(now[axis], s.gravity[axis], side)) return;
        away[w] = false;
        for (let i = 0; i < 2; ++i) if (i !== axis) now[i] *= s.beta;
        ball.setLinearVelocity(lib.Vec2(now[0], now[1]));
      });
    }

    const timestep = s.dt;
    return {
      step: perContact
        ? () => {
          world.step(timestep, velocityIterations, positionIterations);
          const v = ball.getLinearVelocity();
          for (let w = 0; w < walls.length; ++w)
            if ((walls[w].axis === 0 ? v.x : v.y) * walls[w].side < -eps) away[w] = true;
        }
        : () => world.step(timestep, velocityIterations, positionIterations),
      read: (out) => {
        const p = ball.getPosition(), v = ball.getLinearVelocity();
        out[0] = p.x; out[1] = p.y; out[2] = v.x; out[3] = v.y;
      },
      free() {},
    };
  },
};

await serve(adapter);
