// Box2D 2.4.1 (npm box2d-wasm 7.0.0: Erin Catto's Box2D v2.4.1 compiled to
// WebAssembly by Emscripten with WebIDL bindings; 32-bit floats) as a
// bouncecheck simulator: `box2d-wasm`, 2D only. It is the same Box2D version
// as Debian's libbox2d 2.4.1, which the compiled `box2d` simulator links
// (engines/box2d/box2d_adapter.cpp), and it builds the same world with the
// same settings, call for call, so the two builds can be compared. The
// protocol and the stepping loop are host/protocol.mjs's; this file builds
// the world. Every setting that changes the answer is one of the
// [engines.box2d-wasm] keys below, defaulting to the value chosen here (the
// compiled adapter's Tuning); each `why` says what Box2D's own default does,
// measured (docs/engines.md, Box2D 2.4.1 from npm).
//
// How a bounce happens in Box2D 2.4.1 (b2_world.cpp, b2_island.cpp,
// b2_contact_solver.cpp): Step() first updates the contacts (a contact touches
// when the shapes overlap, the polygons' 1 cm skin b2_polygonRadius included)
// and calls BeginContact for each new touch; then it integrates gravity,
// solves the velocity constraints (restitution: the normal velocity after the
// solve is -restitution x the normal velocity before it, if that approached
// faster than the contact's restitutionThreshold), integrates positions and
// pushes penetration deeper than b2_linearSlop back out (position only). With
// continuous physics a ball that would sink more than 3 b2_linearSlop into a
// static wall during the step is moved back to its time of impact and the rest
// of the step is solved from there (BeginContact and restitution included).
//
// There is no world-wide velocity threshold in 2.4.1: b2_velocityThreshold of
// 2.3 became b2FixtureDef::restitutionThreshold (b2_fixture.h:69, default
// 1 m/s x b2_lengthUnitsPerMeter), mixed per contact by min
// (b2MixRestitutionThreshold, b2_contact.h:55). It is set here on every
// fixture. The lengths b2_linearSlop (5 mm), b2_polygonRadius (1 cm) and
// b2_maxTranslation (2 m per step) are compile-time (b2_common.h:65, 74, 95,
// b2_lengthUnitsPerMeter 1 in b2_settings.h:49); as in the compiled adapter the
// world is scaled so the ball is 1 m in the engine, which makes them 0.5%, 1%
// and 200% of the radius.
//
// Per-contact mode: a JSContactListener's BeginContact (called from
// b2Contact::Update, at the start of Step() or at a time of impact, before the
// solve) scales the ball's velocity along the wall by beta once if the ball
// moves into the wall, through b2Body::SetLinearVelocity: the compiled
// adapter's ContactHook, line for line.
//
// Measured: its rows are byte-identical to the compiled box2d's (Debian's
// libbox2d 2.4.1, GCC 12, x86-64) on seed-2d at dt 0.03 and 1e-3 in both
// modes, the three bar scenarios in both modes and three 2D stress scenarios:
// both compute in binary32 without fused multiply-add, in the same order.

import fs from 'node:fs';
import { createRequire } from 'node:module';
import { serve, ScenarioError, roomWalls, maxBallSpeed, movesIntoWall, ownKey, count1, nonNegative, trueOrFalse } from './host/protocol.mjs';

// The package's UMD build without SIMD, loaded by its path with the bytes of
// its .wasm: the ES build refers to __dirname, which an ES module under Node
// does not have, and Emscripten's own loader would fetch the file. The SIMD
// build is the same scalar Box2D (its rows were byte-identical on seed-2d).
const require = createRequire(import.meta.url);
const DIST = new URL('./node_modules/box2d-wasm/dist/umd/', import.meta.url);
const BUILD = 'Box2D.js';
const WASM = 'Box2D.wasm';

const ownKeys = {
  length_scale: 'engine metres per scenario metre (default 0: 1 / radius, the ball is 1 m in the engine, as the compiled box2d; Box2D has no scale: 1)',
  restitution_threshold: 'b2FixtureDef::restitutionThreshold on ball and walls, engine m/s: slower contacts do not bounce (default 0; Box2D default 1)',
  wall_restitution: 'restitution of the walls (default: alpha, as the ball; Box2D default 0, combined by max)',
  wall_friction: 'friction of the walls (default: the ball\'s mu; Box2D default 0.2, combined by sqrt(mu1 mu2))',
  combine_override: 'set mu, alpha and the threshold on every contact in PreSolve, whatever the mixing rules give (default true, as the compiled box2d; Box2D: mixed fixture values)',
  skin_compensation: 'wall faces b2_polygonRadius (1 cm engine) outside the room, so the skinned surface is the wall (default true; Box2D: the skin sits inside the room)',
  sleeping: 'b2World::SetAllowSleeping and the ball\'s allowSleep (default false; Box2D default true)',
  velocity_iterations: 'b2World::Step velocity iterations (default 8, the testbed\'s)',
  position_iterations: 'b2World::Step position iterations (default 3, the testbed\'s)',
  warm_starting: 'b2World::SetWarmStarting (default true, Box2D\'s)',
  linear_damping: 'the ball\'s linear damping (default 0, Box2D\'s)',
  angular_damping: 'the ball\'s angular damping (default 0, Box2D\'s)',
};

function fail(message) { throw new ScenarioError(message); }

const adapter = {
  name: 'box2d-wasm',
  dimensions: [2],
  precision: 'f32',
  packages: () => ['box2d-wasm'],
  ownKeys,

  async load() {
    const factory = require(new URL(BUILD, DIST).pathname);
    return factory({ wasmBinary: fs.readFileSync(new URL(WASM, DIST)) });
  },

  // The bindings do not expose b2_version (which says 2.4.0 in the 2.4.1
  // sources, b2_settings.cpp); the package's README pins v2.4.1.
  version: () => 'Box2D 2.4.1',

  build(lib, s, settings) {
    const e = s.engine;
    const perContact = e.tangential_model === 'per-contact';
    if (perContact && e.friction !== 0) fail('[engines.box2d-wasm] per-contact mode runs with friction 0');
    const mu = Math.fround(perContact ? 0 : e.friction);
    const alpha = Math.fround(s.alpha);
    const beta = Math.fround(s.beta);
    const continuous = e.ccd === undefined ? true : e.ccd;

    const lengthScale = ownKey(s, 'length_scale', 0, nonNegative);
    const threshold = Math.fround(ownKey(s, 'restitution_threshold', 0, nonNegative));
    const wallRestitution = Math.fround(ownKey(s, 'wall_restitution', alpha, nonNegative));
    const wallFriction = Math.fround(ownKey(s, 'wall_friction', mu, nonNegative));
    const override = ownKey(s, 'combine_override', true, trueOrFalse);
    const skinCompensation = ownKey(s, 'skin_compensation', true, trueOrFalse);
    const sleeping = ownKey(s, 'sleeping', false, trueOrFalse);
    const velocityIterations = ownKey(s, 'velocity_iterations', 8, count1);
    const positionIterations = ownKey(s, 'position_iterations', 3, count1);
    const warmStarting = ownKey(s, 'warm_starting', true, trueOrFalse);
    const linearDamping = ownKey(s, 'linear_damping', 0, nonNegative);
    const angularDamping = ownKey(s, 'angular_damping', 0, nonNegative);
    const B = lib;

    // The compiled adapter's UnitScale (engines/engine.h), in doubles, time 1.
    const scale = lengthScale > 0 ? lengthScale : 1.0 / s.radius;
    const L = (x) => x * scale;                 // to_engine_length, velocity, acceleration
    const fromEngine = (x) => x / scale;        // from_engine_length, velocity
    const dt = Math.fround(s.dt);

    const temps = [];
    const vec = (x, y) => { const v = new B.b2Vec2(x, y); temps.push(v); return v; };
    const gravity = [Math.fround(L(s.gravity[0])), Math.fround(L(s.gravity[1]))];
    const world = new B.b2World(vec(gravity[0], gravity[1]));
    world.SetAllowSleeping(sleeping);
    world.SetContinuousPhysics(continuous);
    world.SetSubStepping(false);
    world.SetWarmStarting(warmStarting);

    // The room: one static body, one box per wall, thick and long enough to
    // cover the corners, its face b2_polygonRadius outside the room so that
    // the skinned surface (face + skin) is the wall (box2d_adapter.cpp).
    const roomDef = new B.b2BodyDef();
    roomDef.set_type(B.b2_staticBody);
    const room = world.CreateBody(roomDef);
    B.destroy(roomDef);
    const size = [L(s.room[0]), L(s.room[1])];
    const halfThick = Math.max(size[0], size[1]) / 2;
    const box = new B.b2PolygonShape();
    const polygonRadius = box.get_m_radius();   // b2_polygonRadius, 0.01f
    const skin = skinCompensation ? polygonRadius : 0;
    const walls = roomWalls(s);
    const wallOf = new Map();  // fixture pointer -> index in `walls`
    for (let index = 0; index < walls.length; ++index) {
      const w = walls[index];
      const other = 1 - w.axis;
      const halfLen = size[other] / 2 + 2 * halfThick;
      const face = L(w.offset) + w.side * skin;
      const centre = [0, 0];
      centre[w.axis] = Math.fround(face + w.side * halfThick);
      centre[other] = Math.fround(size[other] / 2);
      const hx = Math.fround(w.axis === 0 ? halfThick : halfLen);
      const hy = Math.fround(w.axis === 0 ? halfLen : halfThick);
      box.SetAsBox(hx, hy, vec(centre[0], centre[1]), 0);
      const fd = new B.b2FixtureDef();
      fd.set_shape(box);
      fd.set_friction(wallFriction);
      fd.set_restitution(wallRestitution);
      fd.set_restitutionThreshold(threshold);
      const fixture = room.CreateFixture(fd);
      B.destroy(fd);
      wallOf.set(B.getPointer(fixture), index);
    }
    B.destroy(box);

    const ballDef = new B.b2BodyDef();
    ballDef.set_type(B.b2_dynamicBody);
    ballDef.set_position(vec(Math.fround(L(s.position[0])), Math.fround(L(s.position[1]))));
    ballDef.set_linearVelocity(vec(Math.fround(L(s.velocity[0])), Math.fround(L(s.velocity[1]))));
    ballDef.set_allowSleep(sleeping);
    ballDef.set_awake(true);
    ballDef.set_fixedRotation(e.rotation === 'locked');
    ballDef.set_bullet(false);
    ballDef.set_linearDamping(linearDamping);
    ballDef.set_angularDamping(angularDamping);
    ballDef.set_gravityScale(1);
    const ball = world.CreateBody(ballDef);
    B.destroy(ballDef);
    const circle = new B.b2CircleShape();
    circle.set_m_p(vec(0, 0));
    circle.set_m_radius(Math.fround(L(s.radius)));
    const bd = new B.b2FixtureDef();
    bd.set_shape(circle);
    bd.set_density(1);
    bd.set_friction(mu);
    bd.set_restitution(alpha);
    bd.set_restitutionThreshold(threshold);
    ball.CreateFixture(bd);
    B.destroy(bd);
    B.destroy(circle);

    // The ball's position (m_xf.p) and velocity (m_linearVelocity) as indices
    // into the module's Float32Array: b2Body::GetPosition and
    // GetLinearVelocity return references into the body, which Box2D never
    // moves. A step's state is read with no call into WebAssembly.
    const positionAt = B.getPointer(ball.GetPosition()) >> 2;
    const velocityAt = B.getPointer(ball.GetLinearVelocity()) >> 2;

    // The contact hook. The compiled adapter's PreSolve sets mu, alpha and the
    // threshold on every contact; when the fixtures already mix to exactly
    // those (walls as the ball: sqrtf(mu mu) = mu in binary32, max and min of
    // equal values), it changes nothing, and is not installed (it would cost a
    // call from WebAssembly into JS and three back, every touching step).
    const mixedExact = wallFriction === mu && wallRestitution === alpha;
    const needPreSolve = override && !mixedExact;
    let listener = null;
    const newVelocity = new B.b2Vec2(0, 0);
    if (perContact || needPreSolve) {
      listener = new B.JSContactListener();
      listener.BeginContact = perContact
        ? (contactPtr) => {
          const contact = B.wrapPointer(contactPtr, B.b2Contact);
          let w = wallOf.get(B.getPointer(contact.GetFixtureA()));
          if (w === undefined) w = wallOf.get(B.getPointer(contact.GetFixtureB()));
          if (w === undefined) return;
          const { axis, side } = walls[w];
          const heap = B.HEAPF32;
          const vx = heap[velocityAt], vy = heap[velocityAt + 1];
          if (!movesIntoWall(axis === 0 ? vx : vy, gravity[axis], side)) return;
          newVelocity.set_x(axis === 0 ? vx : Math.fround(vx * beta));
          newVelocity.set_y(axis === 0 ? Math.fround(vy * beta) : vy);
          ball.SetLinearVelocity(newVelocity);
        }
        : () => {};
      listener.EndContact = () => {};
      listener.PreSolve = needPreSolve
        ? (contactPtr) => {
          const contact = B.wrapPointer(contactPtr, B.b2Contact);
          contact.SetFriction(mu);
          contact.SetRestitution(alpha);
          contact.SetRestitutionThreshold(threshold);
        }
        : () => {};
      listener.PostSolve = () => {};
      world.SetContactListener(listener);
    }

    const maxMove = L(maxBallSpeed(s)) * s.dt;
    const maxTranslation = 2;   // b2_maxTranslation, b2_common.h:95
    const add = (key, value, why) => settings.add(key, value, why);
    add('build', 'umd/Box2D.wasm (no SIMD)', 'the package\'s scalar build, loaded by path with its bytes as wasmBinary; Emscripten, binary32 with no fused multiply-add (WebAssembly has none)');
    add('length_scale', `${scale} (ball radius ${Math.fround(L(s.radius))} m in the engine)`,
      lengthScale > 0 ? '[engines.box2d-wasm] length_scale'
        : 'the compiled box2d\'s: 1 / radius. Box2D\'s scale 1 (5 mm slop, 1 cm skin, a 1.5 cm TOI target against a 5 cm ball): seed-2d per-contact at dt 0.03 the time of impact never fires (the same rows as ccd = false): 4.93 mm beyond the floor against 0.64, apex 2 0.6259 m against 0.6160 (exact 0.6187); at dt 1e-3 nearly no change; with the 1 m/s threshold as well, no bounce at all (the ball lies on the floor from 4.294 s)');
    add('gravity', `(${gravity.join(', ')}) engine m/s^2`, 'the scenario\'s, scaled; gravity scale 1');
    add('dt_engine', `${dt} (float)`, 'b2World::Step once per engine step');
    add('restitution_threshold', `${threshold} m/s (engine)`,
      'b2FixtureDef::restitutionThreshold on ball and walls, min-mixed per contact (a fixture value in 2.4.1, b2_fixture.h:69; there is no compile-time b2_velocityThreshold). Box2D\'s default 1 m/s (engine: 5 cm/s at the seed\'s scale 20): seed-2d per-contact at dt 1e-3, the last hops stop, the ball lies on the floor from 34.50 s (chosen: 38.20 s) and slides on at 0.056 m/s to the end (chosen: 1.2e-7 m/s); at length_scale 1 no bounce at all');
    add('restitution', `ball ${alpha}, walls ${wallRestitution}`, 'b2MixRestitution is max: the walls at Box2D\'s default 0 give byte-identical rows (seed-2d per-contact, dt 1e-3)');
    add('friction', `ball ${mu}, walls ${wallFriction}`,
      perContact ? 'per-contact mode: mu 0 on the ball; beta from BeginContact'
        : 'Coulomb mu from [engines] friction on the ball; b2MixFriction is sqrt(ball x wall). Walls at Box2D\'s default 0.2: no change while combine_override is on; with it off, mu 0.004 becomes 0.028: seed-2d at dt 1e-3 first floor contact 4.3874 s against 4.2988, apex 2 0.5858 m against 0.6200');
    add('combine_override', override ? (needPreSolve ? 'PreSolve sets mu, alpha and the threshold on every contact' : 'on: the fixtures mix to exactly mu, alpha and the threshold, so no PreSolve is needed') : 'off (mixed fixture values)',
      'the compiled box2d\'s override_mix: exact coefficients whatever the mixing rules make of the fixtures (off with the walls as the ball: byte-identical rows)');
    add('wall_skin', `b2_polygonRadius ${polygonRadius} m (engine), faces placed ${skin} m outside the room`,
      'polygons collide with a skin of b2_polygonRadius (b2_common.h:74). Box2D\'s placement (the skin inside the room) turns the ball 1 cm (engine) early at every wall: seed-2d per-contact at dt 1e-3 the resting ball\'s lowest 0.05042 m against 0.04988 after 26 s; at length_scale 1 the ball floats 1 cm up (lowest 0.0599 m) and never touches the floor');
    add('linear_slop', `${0.005} m engine = ${fromEngine(0.005)} scenario`, 'compile-time (b2_common.h:65): the position solver leaves this much penetration');
    add('sleeping', sleeping ? 'on' : 'off (world and body)', 'Box2D\'s default on (b2_linearSleepTolerance 0.01 m/s engine for b2_timeToSleep 0.5 s): byte-identical rows on seed-2d at dt 1e-3 and 0.03 in both modes, as the ball never stays that slow (it slides at 0.05 m/s with friction; per-contact, each micro-hop\'s BeginContact calls SetLinearVelocity, whose SetAwake(true) zeroes the sleep time)');
    add('ccd', continuous ? 'on (TOI against static walls; bullet off, sub-stepping off)' : 'off',
      e.ccd !== undefined ? 'scenario [engines.box2d-wasm] ccd' : 'Box2D\'s default: the bounce lands at the time of impact inside the step (off: seed-2d per-contact at dt 0.03 goes 4.93 mm beyond the floor against 0.64)');
    add('iterations', `velocity ${velocityIterations}, position ${positionIterations} (TOI: 20, fixed)`,
      'the compiled box2d\'s (Box2D\'s testbed values; Step has no default). 1 velocity iteration: friction mode mu 0.004 at dt 1e-3, apex 3 0.4149 m against 0.4129 and the final slide 0.062 m/s against 0.051; 1 position iteration: the same rows at dt 0.03');
    add('warm_starting', warmStarting ? 'on' : 'off', 'Box2D\'s default (off: byte-identical rows, friction mode at dt 1e-3: one contact point)');
    add('damping', `linear ${linearDamping}, angular ${angularDamping}`, 'Box2D\'s defaults, set explicitly (linear 0.1: apex 2 0.4086 m against 0.6190)');
    add('max_translation', `b2_maxTranslation ${maxTranslation} m/step (engine, compile-time); largest expected ${maxMove.toPrecision(3)} m/step`,
      maxMove < maxTranslation ? 'below the cap: velocity never clamped' : 'ABOVE the cap: Box2D will clamp the ball\'s speed');
    add('rotation', e.rotation, e.rotation === 'locked' ? 'b2BodyDef::fixedRotation' : 'the ball spins freely (rolling takes part in friction)');
    add('per_contact', perContact ? 'BeginContact, b2Body::SetLinearVelocity' : 'off',
      perContact ? 'JSContactListener::BeginContact (contact update at the start of Step or at a time of impact, before the solve) scales the velocity along the wall by beta once if the ball moves into the wall, as the compiled box2d\'s ContactHook. Known deviation (shared): a ball resting on a wall micro-hops, its contact ends and begins again, and beta damps a slide the law leaves alone'
        : 'friction mode');
    for (const v of temps) B.destroy(v);

    const heap = () => B.HEAPF32;
    return {
      step: () => world.Step(dt, velocityIterations, positionIterations),
      read(out) {
        const h = heap();
        out[0] = fromEngine(h[positionAt]);
        out[1] = fromEngine(h[positionAt + 1]);
        out[2] = fromEngine(h[velocityAt]);
        out[3] = fromEngine(h[velocityAt + 1]);
      },
      free() {
        B.destroy(world);
        if (listener !== null) B.destroy(listener);
        B.destroy(newVelocity);
      },
    };
  },
};

await serve(adapter);
