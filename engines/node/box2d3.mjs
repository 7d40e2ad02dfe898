// Box2D v3 (npm box2d3-wasm 5.2.0: Erin Catto's Box2D at commit 3a4f0da8,
// v3.1.1 plus 18 commits, which calls itself 3.2.0; WebAssembly, 32-bit
// floats) as a bouncecheck simulator: `box2d3`, 2D only. The protocol and the
// stepping loop are host/protocol.mjs's; this file builds the world. Every
// setting that changes the answer is one of the [engines.box2d3] keys below,
// defaulting to the value chosen here; each `why` says what Box2D's own default
// does, measured (docs/engines.md, Box2D v3).
//
// How a Box2D v3 step goes (physics_world.c, contact.c, contact_solver.c,
// solver.c at 3a4f0da8): the collide pass updates every contact from the
// positions the step starts with; a contact is touching when its manifold has
// a point, and a point exists within the speculative distance (4 x the linear
// slop, 2 cm: fixed at compile time, the bindings do not expose
// b2SetLengthUnitsPerMeter); the pre-solve callback sees each touching contact
// there. The solver then stores each point's approach speed
// (`relativeVelocity`, the velocity the step starts with), runs the substeps
// (gravity, a soft contact: rigid while separated, a spring of 2 x contactHertz
// against static bodies once overlapping, pushed out at most contactSpeed) and
// ends with the restitution pass: a point that carried an impulse and
// approached faster than restitutionThreshold leaves at restitution x its
// approach speed.
//
// Per-contact mode: the pre-solve callback (b2World_SetPreSolveCallback, on
// the ball's shape only) records which walls the engine holds a contact with
// this step; after the step, TurnedContacts (host/protocol.mjs) counts the law's contact
// in the step in which the ball stops moving into such a wall, and the other
// velocity component is scaled by beta then, once.

import { serve, ScenarioError, TurnedContacts, roomWalls, ownKey, count1, nonNegative, trueOrFalse } from './host/protocol.mjs';

// The package's `compat` build (no SIMD, no threads), loaded by its path: the
// package's entry point picks its `deluxe` build (SIMD, a pool of 4 pthreads)
// under Node. The two are the same Box2D, and gave byte-identical rows
// (seed-2d per-contact, game-throw-2d with friction 0.05, small-2d per-contact);
// compat loads in about a third of the time and starts no threads.
const BUILD = new URL('./node_modules/box2d3-wasm/build/dist/es/compat/Box2D.compat.mjs', import.meta.url).href;

const ownKeys = {
  restitution_threshold: 'b2WorldDef.restitutionThreshold in m/s: slower contacts do not bounce (default 0; Box2D default 1)',
  wall_restitution: 'restitution of the walls (default: alpha, as the ball; Box2D default 0, combined by max)',
  wall_friction: 'friction of the walls (default: the ball\'s mu; Box2D default 0.6, combined by sqrt(mu1 mu2))',
  sleeping: 'b2WorldDef.enableSleep and the ball\'s enableSleep (default false; Box2D default true)',
  substep_count: 'b2World_Step\'s subStepCount (default 4, Box2D\'s recommended value)',
  contact_hertz: 'b2WorldDef.contactHertz: the contact spring (x2 against static bodies) (default 30, Box2D\'s)',
  contact_damping_ratio: 'b2WorldDef.contactDampingRatio (default 10, Box2D\'s)',
  contact_push_speed: 'the largest speed an overlap is pushed out at, m/s (b2World_SetContactTuning; default 3, Box2D\'s)',
  linear_damping: 'the ball\'s linear damping (default 0, Box2D\'s)',
  angular_damping: 'the ball\'s angular damping (default 0, Box2D\'s)',
};

function fail(message) { throw new ScenarioError(message); }

const adapter = {
  name: 'box2d3',
  dimensions: [2],
  precision: 'f32',
  packages: () => ['box2d3-wasm'],
  ownKeys,

  async load() {
    const factory = (await import(BUILD)).default;
    return factory();
  },

  version: () => 'Box2D 3.2.0 (3a4f0da8, v3.1.1+18)',

  build(lib, s, settings) {
    const e = s.engine;
    const perContact = e.tangential_model === 'per-contact';
    if (e.tangential_model !== 'friction' && !perContact) fail('[engines.box2d3] tangential_model must be "friction" or "per-contact"');
    if (e.rotation !== 'free' && e.rotation !== 'locked') fail('[engines.box2d3] rotation must be "free" or "locked"');
    if (perContact && e.friction !== 0) fail('[engines.box2d3] per-contact mode runs with friction 0');
    const mu = perContact ? 0 : e.friction;
    const ccd = e.ccd === undefined ? true : e.ccd;
    if (typeof ccd !== 'boolean') fail('[engines.box2d3] ccd must be true or false');

    const threshold = ownKey(s, 'restitution_threshold', 0, nonNegative);
    const wallRestitution = ownKey(s, 'wall_restitution', s.alpha, nonNegative);
    const wallFriction = ownKey(s, 'wall_friction', mu, nonNegative);
    const sleeping = ownKey(s, 'sleeping', false, trueOrFalse);
    const substepCount = ownKey(s, 'substep_count', 4, count1);
    const hertz = ownKey(s, 'contact_hertz', 30, nonNegative);
    const dampingRatio = ownKey(s, 'contact_damping_ratio', 10, nonNegative);
    const pushSpeed = ownKey(s, 'contact_push_speed', 3, nonNegative);
    const linearDamping = ownKey(s, 'linear_damping', 0, nonNegative);
    const angularDamping = ownKey(s, 'angular_damping', 0, nonNegative);
    const B = lib;

    const vec = (x, y) => new B.b2Vec2(x, y);
    const worldDef = B.b2DefaultWorldDef();
    worldDef.gravity = vec(s.gravity[0], s.gravity[1]);
    worldDef.restitutionThreshold = threshold;
    worldDef.enableSleep = sleeping;
    worldDef.enableContinuous = ccd;
    worldDef.contactHertz = hertz;
    worldDef.contactDampingRatio = dampingRatio;
    worldDef.workerCount = 0;
    const world = B.b2CreateWorld(worldDef);
    worldDef.delete();
    B.b2World_SetContactTuning(world, hertz, dampingRatio, pushSpeed);

    // The walls: one static body, a box per wall lying outside the room with
    // its face exactly on the wall (Box2D v3 polygons have no skin), as thick
    // as the room is large and overlapping at the corners.
    const walls = roomWalls(s);
    const thick = Math.max(...s.room);
    const wallDef = B.b2DefaultBodyDef();
    const wallBody = B.b2CreateBody(world, wallDef);
    wallDef.delete();
    const wallShapeDef = B.b2DefaultShapeDef();
    wallShapeDef.material.restitution = wallRestitution;
    wallShapeDef.material.friction = wallFriction;
    const wallOf = new Map();  // shape index1 -> index in `walls`
    walls.forEach((w, index) => {
      const half = [s.room[0] / 2 + thick, s.room[1] / 2 + thick];
      half[w.axis] = thick / 2;
      const centre = [s.room[0] / 2, s.room[1] / 2];
      centre[w.axis] = w.offset + w.side * thick / 2;
      const box = B.b2MakeOffsetBox(half[0], half[1], vec(centre[0], centre[1]), B.b2Rot_identity);
      const id = B.b2CreatePolygonShape(wallBody, wallShapeDef, box);
      box.delete();
      wallOf.set(id.index1, index);
    });
    wallShapeDef.delete();

    const bodyDef = B.b2DefaultBodyDef();
    bodyDef.type = B.b2BodyType.b2_dynamicBody;
    bodyDef.position = vec(s.position[0], s.position[1]);
    bodyDef.linearVelocity = vec(s.velocity[0], s.velocity[1]);
    bodyDef.enableSleep = sleeping;
    bodyDef.linearDamping = linearDamping;
    bodyDef.angularDamping = angularDamping;
    bodyDef.gravityScale = 1;
    if (e.rotation === 'locked') {
      const locks = bodyDef.motionLocks;
      locks.angularZ = true;
      bodyDef.motionLocks = locks;
    }
    const ball = B.b2CreateBody(world, bodyDef);
    bodyDef.delete();
    const circle = new B.b2Circle();
    circle.center = vec(0, 0);
    circle.radius = s.radius;
    const ballShapeDef = B.b2DefaultShapeDef();
    ballShapeDef.material.restitution = s.alpha;
    ballShapeDef.material.friction = mu;
    ballShapeDef.density = 1;
    ballShapeDef.enablePreSolveEvents = perContact;
    B.b2CreateCircleShape(ball, ballShapeDef, circle);
    ballShapeDef.delete();
    circle.delete();

    const add = (key, value, why) => settings.add(key, value, why);
    add('gravity', `(${s.gravity.join(', ')})`, 'the scenario\'s, in b2WorldDef (Box2D\'s default (0, -10)); gravity scale 1');
    add('build', 'compat', 'box2d3-wasm\'s build without SIMD and threads; its deluxe build (SIMD, 4 pthreads, what the package picks under Node) gave byte-identical rows, loading in 3x the time');
    add('substep_count', substepCount, 'b2World_Step(world, dt, substep_count): Box2D\'s own substeps within a step (4 is Box2D\'s recommended value; b2World_Step has no default. 1: seed-2d at dt 0.03 third apex 0.2546 m instead of 0.2625, exact 0.2779; 8: 0.2674)');
    add('restitution_threshold', threshold, 'b2WorldDef.restitutionThreshold (Box2D\'s default 1 m/s: seed-2d\'s 0.42 m/s floor impact does not bounce at all, the ball stays on the floor from t = 4.29 s, at dt 1e-3 and 0.03)');
    add('ball_restitution', s.alpha, 'alpha, on the ball\'s shape');
    add('wall_restitution', wallRestitution, 'on every wall (Box2D\'s default 0; restitution combines by max, so alpha either way: seed-2d\'s rows identical)');
    add('restitution_combine', 'max', 'Box2D\'s default b2MixRestitution, kept');
    add('friction', mu, perContact ? 'per-contact mode: 0 on the ball' : 'Coulomb mu from [engines] friction, on the ball');
    add('wall_friction', wallFriction, 'on every wall, equal to the ball\'s (Box2D\'s default 0.6, combined by sqrt(mu1 mu2): friction mode with mu 0.004 gets 0.049, seed-2d\'s first apex after the start 0.5893 m instead of 0.6225; none in per-contact mode, sqrt(0 x 0.6) = 0)');
    add('friction_combine', 'sqrt(mu1 mu2)', 'Box2D\'s default b2MixFriction, kept; both shapes carry mu, so the contact gets mu');
    add('rolling_resistance', 0, 'Box2D\'s default, on every shape');
    add('sleeping', sleeping, 'b2WorldDef.enableSleep and the ball\'s (Box2D\'s default true: seed-2d at dt 1e-3, the ball sliding on the floor at 0.046 m/s freezes at t = 48.54 s)');
    add('damping', `linear ${linearDamping}, angular ${angularDamping}`, 'Box2D\'s defaults, set explicitly');
    add('contact_softness', `${hertz} Hz (x2 against static bodies), damping ratio ${dampingRatio}, push-out at most ${pushSpeed} m/s`, 'Box2D\'s defaults (b2WorldDef, b2World_SetContactTuning)');
    add('slop', '5 mm linear slop, 2 cm speculative distance', 'compile-time (B2_LINEAR_SLOP, B2_SPECULATIVE_DISTANCE at b2_lengthUnitsPerMeter 1; not exposed by the bindings)');
    add('ccd', ccd, ccd ? 'b2WorldDef.enableContinuous, Box2D\'s default: a fast ball is swept against the static walls (off: no effect measured on seed-2d at dt 1e-3 and 0.03)' : 'continuous collision off ([engines] ccd = false)');
    add('maximum_linear_speed', '400 m/s', 'Box2D\'s default, kept');
    add('rotation', e.rotation, e.rotation === 'locked' ? 'the ball\'s motionLocks.angularZ' : 'the ball spins freely');
    add('walls', 'boxes outside the room, faces on the walls', 'one static body, a box per wall, as thick as the room is large');
    add('per_contact', perContact ? 'pre-solve callback, velocity scaled after the step' : 'off',
      perContact ? 'the pre-solve callback tells which walls the engine touches in the step; beta is applied after the step in which the ball stopped moving into one (TurnedContacts)' : 'friction mode');

    const d = 2;
    const timestep = s.dt;
    const contacts = perContact ? new TurnedContacts(s) : null;
    const touching = new Array(walls.length).fill(false);
    const touchedNow = new Array(walls.length).fill(false);
    const before = Float64Array.from(s.velocity);
    const now = new Float64Array(d);
    const pos = new Float64Array(d);
    const velocityOut = new B.b2Vec2(0, 0);
    let callback = null;
    if (perContact) {
      callback = B.b2World_SetPreSolveCallback(world, (shapeA, shapeB, point, normal) => {
        const w = wallOf.has(shapeA.index1) ? wallOf.get(shapeA.index1) : wallOf.get(shapeB.index1);
        if (w !== undefined) touchedNow[w] = true;
        point.delete();
        normal.delete();
        return true;
      });
    }
    const readState = () => {
      const p = B.b2Body_GetPosition(ball);
      const v = B.b2Body_GetLinearVelocity(ball);
      pos[0] = p.x; pos[1] = p.y; now[0] = v.x; now[1] = v.y;
      p.delete();
      v.delete();
    };

    return {
      step: perContact
        ? () => {
          B.b2World_Step(world, timestep, substepCount);
          readState();
          for (let w = 0; w < touching.length; ++w) { touching[w] = touchedNow[w]; touchedNow[w] = false; }
          const axes = contacts.turned(touching, before, now);
          if (axes.length) {
            for (let i = 0; i < d; ++i) if (!axes.includes(i)) now[i] *= s.beta;
            velocityOut.x = now[0];
            velocityOut.y = now[1];
            B.b2Body_SetLinearVelocity(ball, velocityOut);
          }
          before.set(now);
        }
        : () => B.b2World_Step(world, timestep, substepCount),
      read: perContact
        ? (out) => { out[0] = pos[0]; out[1] = pos[1]; out[2] = now[0]; out[3] = now[1]; }
        : (out) => { readState(); out[0] = pos[0]; out[1] = pos[1]; out[2] = now[0]; out[3] = now[1]; },
      free() {
        if (callback !== null) B.b2World_DeleteCallback(callback);
        velocityOut.delete();
        B.b2DestroyWorld(world);
      },
    };
  },
};

await serve(adapter);
