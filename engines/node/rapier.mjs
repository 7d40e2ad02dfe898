// Rapier (the Rust engine's official WebAssembly bindings, @dimforge/rapier2d-compat
// and @dimforge/rapier3d-compat) as a bouncecheck simulator: `rapier`, 2D and 3D,
// 32-bit floats. The protocol and the stepping loop are host/protocol.mjs's; this
// file builds the world. Every setting that changes the answer is one of the
// [engines.rapier] keys below, defaulting to the value chosen here; each `why`
// says what Rapier's own default does, measured (docs/engines.md, Rapier).
//
// What Rapier does at a contact, read in github:dimforge/rapier at ccd01cd2 (after
// Rapier 0.35.2, whose JS bindings were 0.20.0; npm's 0.21.0 is newer than that
// history, and behaved as read in every probe):
// - restitution: no velocity threshold. A contact point that carried no impulse
//   at the previous step is "new" and bouncy if its combined restitution is > 0
//   (`is_bouncy`, geometry/contact_pair.rs); an end-of-step pass then drives its
//   normal velocity to restitution x the approach velocity the step started with,
//   if the point carried an impulse this step (`solve_restitution`,
//   contact_constraint_element.rs). A point still loaded from the last step is a
//   resting contact and does not bounce (unless restitution >= 1).
// - contacts are speculative: a ball within the prediction distance of a wall, or
//   that would reach it within the step, holds a contact (and a collision-start
//   event) before it touches (`keep_solver_contact`, narrow_phase/pair_update.rs).
// - penetration is corrected by a soft spring (60 Hz, damping ratio 10, against
//   fixed bodies), capped at 3 m/s x lengthUnit; there is no deadzone.
//
// Per-contact mode: Rapier's JS bindings have no contact-modification hook (only
// the pair filters), so the ball's collision-start and -stop events, drained
// after each step, say which walls the engine holds a contact with, and
// TurnedContacts (host/protocol.mjs) counts the law's contact in the step in which the ball
// stopped moving into such a wall: the other velocity components are scaled by
// beta then, once, before the next step.

import { serve, ScenarioError, TurnedContacts, roomWalls, ownKey, count0, count1, nonNegative, positive, trueOrFalse, oneOf } from './host/protocol.mjs';

const RULES = { average: 0, min: 1, multiply: 2, max: 3 };
const RULE = oneOf(...Object.keys(RULES));  // the kind of the *_combine keys

const ownKeys = {
  wall_restitution: 'restitution of the walls (default: alpha, as the ball; Rapier default 0)',
  restitution_combine: 'restitution combine rule of every collider: average, min, multiply or max (default average, Rapier\'s)',
  wall_friction: 'friction of the walls (default: the ball\'s mu; Rapier default 0.5)',
  friction_combine: 'friction combine rule of every collider: average, min, multiply or max (default average, Rapier\'s)',
  sleeping: 'whether the ball may sleep (default false; Rapier default true)',
  linear_damping: 'the ball\'s linear damping (default 0, Rapier\'s)',
  angular_damping: 'the ball\'s angular damping (default 0, Rapier\'s)',
  timestep: 'Rapier\'s integration step in seconds (default: the scenario\'s dt / substeps; Rapier default 1/60)',
  solver_iterations: 'numSolverIterations: Rapier\'s solver substeps per step (default 4, Rapier\'s)',
  pgs_iterations: 'numInternalPgsIterations per solver iteration (default 1, Rapier\'s)',
  prediction_distance: 'normalizedPredictionDistance: the speculative-contact distance, x length_unit (default 0; Rapier default 0.02)',
  allowed_linear_error: 'normalizedAllowedLinearError: the CCD clamp\'s standoff, x length_unit (default 0.005, Rapier\'s)',
  length_unit: 'lengthUnit: Rapier\'s units per metre, scaling its tolerances (default 1, Rapier\'s)',
  soft_ccd_prediction: 'the ball\'s softCcdPrediction in m: how far ahead along its velocity contacts are looked for (default: the room\'s largest side, so a whole step\'s travel; Rapier default 0)',
  max_ccd_substeps: 'maxCcdSubsteps: 0 turns every CCD off (default 1, Rapier\'s: sweep-based CCD of fast bodies against fixed colliders)',
};

function fail(message) { throw new ScenarioError(message); }

const adapter = {
  name: 'rapier',
  dimensions: [2, 3],
  precision: 'f32',
  packages: (d) => [d === 3 ? '@dimforge/rapier3d-compat' : '@dimforge/rapier2d-compat'],
  ownKeys,

  async load(d) {
    const module = d === 3 ? await import('@dimforge/rapier3d-compat') : await import('@dimforge/rapier2d-compat');
    const R = module.default ?? module;
    await R.init();
    return R;
  },

  version: (R) => `Rapier ${R.version()}`,

  build(R, s, settings) {
    const d = s.dimension;
    const e = s.engine;
    const perContact = e.tangential_model === 'per-contact';
    if (e.tangential_model !== 'friction' && !perContact) fail(`[engines.rapier] tangential_model must be "friction" or "per-contact"`);
    if (e.rotation !== 'free' && e.rotation !== 'locked') fail(`[engines.rapier] rotation must be "free" or "locked"`);
    const mu = perContact ? 0 : e.friction;
    if (perContact && e.friction !== undefined && e.friction !== 0) fail('[engines.rapier] per-contact mode runs with friction 0');
    const ccd = e.ccd === undefined ? true : e.ccd;
    if (typeof ccd !== 'boolean') fail('[engines.rapier] ccd must be true or false');

    const wallRestitution = ownKey(s, 'wall_restitution', s.alpha, nonNegative);
    const restitutionRule = ownKey(s, 'restitution_combine', 'average', RULE);
    const wallFriction = ownKey(s, 'wall_friction', mu, nonNegative);
    const frictionRule = ownKey(s, 'friction_combine', 'average', RULE);
    const sleeping = ownKey(s, 'sleeping', false, trueOrFalse);
    const linearDamping = ownKey(s, 'linear_damping', 0, nonNegative);
    const angularDamping = ownKey(s, 'angular_damping', 0, nonNegative);
    const timestep = ownKey(s, 'timestep', s.dt, positive);
    const iterations = ownKey(s, 'solver_iterations', 4, count1);
    const pgs = ownKey(s, 'pgs_iterations', 1, count1);
    const prediction = ownKey(s, 'prediction_distance', 0, nonNegative);
    const linearError = ownKey(s, 'allowed_linear_error', 0.005, nonNegative);
    const lengthUnit = ownKey(s, 'length_unit', 1, positive);
    const softCcd = ownKey(s, 'soft_ccd_prediction', Math.max(...s.room), nonNegative);
    const ccdSubsteps = ownKey(s, 'max_ccd_substeps', ccd ? 1 : 0, count0);

    const vec = d === 3 ? (a) => ({ x: a[0], y: a[1], z: a[2] }) : (a) => ({ x: a[0], y: a[1] });
    const world = new R.World(vec(s.gravity));
    const p = world.integrationParameters;
    p.dt = timestep;
    p.lengthUnit = lengthUnit;
    p.numSolverIterations = iterations;
    p.numInternalPgsIterations = pgs;
    p.normalizedPredictionDistance = prediction;
    p.normalizedAllowedLinearError = linearError;
    p.maxCcdSubsteps = ccdSubsteps;

    // The walls: one fixed body, a half-space per wall (the solid beyond the
    // plane), so no speed can carry the ball through.
    const walls = roomWalls(s);
    const wallBody = world.createRigidBody(R.RigidBodyDesc.fixed());
    const wallOf = new Map();  // collider handle -> index in `walls`
    walls.forEach((w, index) => {
      const normal = new Array(d).fill(0);
      normal[w.axis] = -w.side;  // pointing into the room
      const at = s.room.map((size) => size / 2);
      at[w.axis] = w.offset;
      const desc = new R.ColliderDesc(new R.HalfSpace(vec(normal)))
        .setTranslation(...at)
        .setRestitution(wallRestitution).setRestitutionCombineRule(RULES[restitutionRule])
        .setFriction(wallFriction).setFrictionCombineRule(RULES[frictionRule]);
      wallOf.set(world.createCollider(desc, wallBody).handle, index);
    });

    const bodyDesc = R.RigidBodyDesc.dynamic()
      .setTranslation(...s.position)
      .setLinvel(...s.velocity)
      .setCanSleep(sleeping)
      .setLinearDamping(linearDamping)
      .setAngularDamping(angularDamping)
      .setGravityScale(1)
      .setSoftCcdPrediction(softCcd);
    if (e.rotation === 'locked') bodyDesc.lockRotations();
    const ball = world.createRigidBody(bodyDesc);
    const ballDesc = R.ColliderDesc.ball(s.radius)
      .setRestitution(s.alpha).setRestitutionCombineRule(RULES[restitutionRule])
      .setFriction(mu).setFrictionCombineRule(RULES[frictionRule]);
    if (perContact) ballDesc.setActiveEvents(R.ActiveEvents.COLLISION_EVENTS);
    world.createCollider(ballDesc, ball);

    const add = (key, value, why) => settings.add(key, value, why);
    add('gravity', `(${s.gravity.join(', ')})`, 'the scenario\'s, given to the World; gravity scale 1');
    add('timestep', timestep, 'integrationParameters.dt: one Rapier step per scenario step (Rapier\'s default 1/60 s whatever dt: at dt 1e-3 time runs 16.7x fast, seed-2d\'s first floor contact at t = 0.258 s instead of 4.294, exact 4.293)');
    add('ball_restitution', s.alpha, 'alpha, on the ball\'s collider');
    add('wall_restitution', wallRestitution, 'on every wall (Rapier\'s default 0, combined by average: restitution alpha/2, seed-2d\'s second apex 0.1936 m instead of 0.6186, exact 0.6187)');
    add('restitution_combine', restitutionRule, 'on every collider (Rapier\'s default rule): both carry alpha, so the contact gets alpha; multiply would give alpha^2, seed-2d\'s second apex 0.4170 m');
    add('restitution_threshold', 'none', 'Rapier has none: a contact point that carried no impulse at the last step bounces at any speed; one loaded at the last step is resting and does not (is_bouncy)');
    add('friction', mu, perContact ? 'per-contact mode: 0 on the ball' : 'Coulomb mu from [engines] friction, on the ball');
    add('wall_friction', wallFriction, 'on every wall, equal to the ball\'s (Rapier\'s default 0.5, combined by average: mu 0.25 in per-contact mode, seed-2d\'s first floor contact at 4.643 s instead of 4.294 and second apex 0.5347 m instead of 0.6186)');
    add('friction_combine', frictionRule, 'on every collider (Rapier\'s default rule); both carry mu, so the contact gets mu');
    add('friction_model', d === 3 ? 'simplified' : 'Coulomb', d === 3 ? 'Rapier\'s 3D default, not exposed to JS: one Coulomb constraint per manifold and a twist constraint on the spin about the normal' : 'one Coulomb constraint per contact point');
    add('sleeping', sleeping, 'the ball\'s canSleep (Rapier\'s default true: seed-2d\'s ball freezes mid-air at t = 25.80 s, 0.142 m up; seed-3d\'s at 30.86 s, 0.054 m up)');
    add('damping', `linear ${linearDamping}, angular ${angularDamping}`, 'Rapier\'s defaults, set explicitly');
    add('solver_iterations', iterations, 'numSolverIterations, Rapier\'s substeps within a step (its default 4, kept; 1: seed-2d at dt 0.03 first and third apexes 0.6051 and 0.2588 m instead of 0.6088 and 0.2660; 8: within 0.1% of 4 at dt 1e-3)');
    add('pgs_iterations', pgs, 'numInternalPgsIterations (Rapier\'s default 1, kept)');
    add('prediction_distance', prediction, `normalizedPredictionDistance: ${prediction * lengthUnit} m of speculative contact, so a contact exists only in the step that reaches the wall (Rapier's default 0.02: a speculative contact turns the ball up to a solver substep before it reaches the wall, earth-drop at dt 1e-3 0.46 mm short of the floor at t = 1.083 s, third apex 1.19% off exact against 0.56%; seed-2d at dt 0.03 second apex 0.3962 m against 0.4023, exact 0.4107)`);
    add('soft_ccd_prediction', softCcd, `the ball's softCcdPrediction: the contact search covers the whole step's travel, so the contact is made in the step that reaches the wall (Rapier's default 0, with prediction_distance 0: the contact comes a step late, seed-2d at dt 0.03 is found 6.32 mm inside the floor, seed-3d 6.83 mm, a 0.5 m ball at 17 m/s 14.8 mm)`);
    add('allowed_linear_error', linearError, 'normalizedAllowedLinearError (Rapier\'s default 0.005, kept): the standoff the CCD clamp keeps; not a penetration deadzone in Rapier 0.35');
    add('length_unit', lengthUnit, 'lengthUnit (Rapier\'s default 1, kept): scenario metres are Rapier metres');
    add('contact_softness', '60 Hz, damping ratio 10 against fixed bodies', 'Rapier\'s defaults, not exposed to JS: how fast an overlap is pushed out, at most 3 m/s x length_unit');
    add('ccd', ccdSubsteps > 0 ? `on (maxCcdSubsteps ${ccdSubsteps})` : 'off', 'Rapier\'s default: a fast body is swept against fixed colliders ([engines] ccd = false or max_ccd_substeps = 0 turn it off: no effect measured on the seeds at dt 1e-3 and 0.03)');
    add('rotation', e.rotation, e.rotation === 'locked' ? 'lockRotations() on the ball' : 'the ball spins freely');
    add('walls', 'half-spaces', 'one per wall, exactly at 0 and the room size, on one fixed body');
    add('per_contact', perContact ? 'collision events, velocity scaled after the step' : 'off',
      perContact ? 'Rapier\'s JS bindings have no contact-modification hook: the collision-start and -stop events say which walls the engine touches; beta is applied after the step in which the ball stopped moving into one (TurnedContacts)' : 'friction mode');

    const queue = perContact ? new R.EventQueue(true) : null;
    const contacts = perContact ? new TurnedContacts(s) : null;
    const touching = new Array(walls.length).fill(false);
    const position = vec(s.position);
    const velocity = vec(s.velocity);
    const axes = d === 3 ? ['x', 'y', 'z'] : ['x', 'y'];
    let before = Float64Array.from(s.velocity);
    const now = new Float64Array(d);
    const onEvent = (h1, h2, started) => {
      const w = wallOf.has(h1) ? wallOf.get(h1) : wallOf.get(h2);
      if (w !== undefined) touching[w] = started;
    };

    return {
      step: perContact
        ? () => {
          world.step(queue);
          ball.translation(position);
          ball.linvel(velocity);
          queue.drainCollisionEvents(onEvent);
          for (let i = 0; i < d; ++i) now[i] = velocity[axes[i]];
          const starting = contacts.turned(touching, before, now);
          if (starting.length) {
            for (let i = 0; i < d; ++i) if (!starting.includes(i)) { now[i] *= s.beta; velocity[axes[i]] = now[i]; }
            ball.setLinvel(velocity, true);
          }
          before.set(now);
        }
        : () => world.step(),
      read: perContact
        ? (out) => {
          for (let i = 0; i < d; ++i) { out[i] = position[axes[i]]; out[d + i] = now[i]; }
        }
        : (out) => {
          ball.translation(position);
          ball.linvel(velocity);
          for (let i = 0; i < d; ++i) { out[i] = position[axes[i]]; out[d + i] = velocity[axes[i]]; }
        },
      free() {
        queue?.free();
        world.free();
      },
    };
  },
};

await serve(adapter);
