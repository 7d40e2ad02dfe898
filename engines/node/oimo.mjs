// Oimo.js (npm oimo 1.0.9, plain JavaScript, so f64) as a bouncecheck
// simulator: protocol bouncecheck-external/1 through host/protocol.mjs
// (`node oimo.mjs`, or `node oimo.mjs --session`).
//
// How a step goes (build/oimo.module.js, World.step, lines 11705-11990):
// broadphase, then the narrow phase on the positions the last step left (a
// sphere-box contact exists only while the shapes overlap: no speculative
// contact, no CCD), then gravity, the sequential-impulse solve and the
// position update (semi-implicit Euler, no damping of any kind). So a ball
// moving into a wall crosses it in one step and is bounced in the next, from
// inside. Oimo's contact solver carries numbers in world units that no option
// changes (ContactConstraint.preSolve, lines 5371-5375):
//   if(rvn>-1) rvn=0;                                  no bounce below 1 unit/s
//   sepV = -(p.penetration+0.005)*invTimeStep*0.05;    0.005 units of overlap allowed
// and so does sleeping (World.callSleep, lines 11695-11700: below 0.2 units/s
// and 0.5 rad/s for 0.5 s). The world is therefore built in scaled units
// (units_per_metre, 1000 by default: millimetres), the scenario converted in
// and the state out; time is not scaled. A warm-started contact point (one
// within 0.02 units of last step's, Contact.updateManifold, line 5630) also
// never bounces (line 5360).
// The world: one dynamic sphere and six static boxes whose inner faces are
// the walls, each as thick as the room is large.
//
// Every setting that changes the answer is an [engines.<name>] key with this
// adapter's value as its default (ownKeys below), so a test can put Oimo's
// own default back; each goes into the run's settings with what Oimo's
// default did, measured (docs/engines.md, Oimo).

import { createRequire } from 'node:module';
import { serve, ScenarioError, roomWalls, ContactStarts, ownKey, aNumberAtLeast, count1, nonNegative, oneOf, trueOrFalse } from './host/protocol.mjs';

// Oimo's own defaults (World constructor, lines 11326-11361; ShapeConfig, lines 2212-2214; World.add, line 12128).
const OIMO = {
  units_per_metre: 1,
  iterations: 8,
  broadphase: 'sweep-and-prune',
  randomizer: true,
  allow_sleep: true,
  wall_friction: 0.2,
  wall_restitution: 0.2,
};

// World's `broadphase` option (lines 11341-11345): 1 brute force, 2 SAP (its default), 3 DBVT.
const BROADPHASES = { 'brute-force': 1, 'sweep-and-prune': 2, 'bounding-volume-tree': 3 };

const ownKeys = {
  units_per_metre: 'the world\'s length unit: Oimo units per metre; positions, sizes, speeds and gravity are scaled by it, time is not (Oimo: its numbers assume 1; here: 1000, millimetres)',
  iterations: 'the contact solver\'s iterations per step (World option `iterations`; Oimo: 8)',
  broadphase: `the broadphase: ${Object.keys(BROADPHASES).join(', ')} (Oimo: sweep-and-prune)`,
  randomizer: 'shuffle the order of the constraints each step (World option `random`; Oimo: true)',
  allow_sleep: 'the ball may fall asleep (Oimo: true; here: false, World.add neverSleep)',
  wall_friction: 'the walls\' friction (Oimo: 0.2; here: the ball\'s mu)',
  wall_restitution: 'the walls\' restitution (Oimo: 0.2; here: alpha)',
};

function fail(message) { throw new ScenarioError(message); }

function build(OIMO_, s, settings) {
  const e = s.engine;
  const perContact = e.tangential_model === 'per-contact';
  if ('ccd' in e && e.ccd !== false) fail('[engines.oimo] ccd: Oimo has none (contacts exist only while the shapes overlap): ccd = false or absent');
  const mu = perContact ? 0 : e.friction;
  const locked = e.rotation === 'locked';

  const U = ownKey(s, 'units_per_metre', 1000, aNumberAtLeast(1e-9));
  const iterations = ownKey(s, 'iterations', OIMO.iterations, count1);
  const broadphase = ownKey(s, 'broadphase', OIMO.broadphase, oneOf(...Object.keys(BROADPHASES)));
  const randomizer = ownKey(s, 'randomizer', OIMO.randomizer, trueOrFalse);
  const allowSleep = ownKey(s, 'allow_sleep', false, trueOrFalse);
  const wallFriction = ownKey(s, 'wall_friction', mu, nonNegative);
  const wallRestitution = ownKey(s, 'wall_restitution', s.alpha, nonNegative);

  const scaled = (v) => v.map((x) => x * U);
  // ---- The world (worldscale left at 1: this adapter scales everything itself) ----
  const world = new OIMO_.World({
    timestep: s.dt, iterations, broadphase: BROADPHASES[broadphase], worldscale: 1, random: randomizer,
    info: false, gravity: scaled(s.gravity),
  });
  // `o.timestep || 1/60`, `o.iterations || 8`: both are given, so neither falls back.
  if (world.timeStep !== s.dt || world.numIterations !== iterations) fail('Oimo did not take the step or the iterations');

  // ---- The walls: static boxes whose inner faces are the walls ----
  const walls = roomWalls(s);
  const thickness = Math.max(...s.room);
  const wallBodies = [];
  for (const w of walls) {
    const centre = s.room.map((l) => l / 2);
    centre[w.axis] = w.side < 0 ? -thickness / 2 : s.room[w.axis] + thickness / 2;
    const size = s.room.map((l) => l + 2 * thickness);
    size[w.axis] = thickness;
    wallBodies.push(world.add({
      type: 'box', size: scaled(size), pos: scaled(centre), move: false,
      friction: wallFriction, restitution: wallRestitution,
    }));
  }

  // ---- The ball ----
  const ball = world.add({
    type: 'sphere', size: [s.radius * U], pos: scaled(s.position), move: true, density: 1,
    friction: mu, restitution: s.alpha, neverSleep: !allowSleep,
  });
  if (locked) {
    // No rotation: zero inverse inertia (syncShapes rebuilds the world-frame one from it each step).
    ball.inverseLocalInertia.set(0, 0, 0, 0, 0, 0, 0, 0, 0);
    ball.inverseInertia.set(0, 0, 0, 0, 0, 0, 0, 0, 0);
  }
  ball.linearVelocity.set(s.velocity[0] * U, s.velocity[1] * U, s.velocity[2] * U);
  ball.angularVelocity.set(0, 0, 0);
  const lv = ball.linearVelocity, pos = ball.position;

  // ---- Per-contact mode: after the step, from the ball's contact links ----
  let afterStep = null, beforeStep = null;
  if (perContact) {
    // Oimo has no contact callback. A wall's contact is `touching` after a
    // step when the narrow phase of that step found the ball overlapping it;
    // the bounce was solved in the same step. So a wall that became touching
    // in this step (ContactStarts, on the velocity before the step) is a
    // contact of the law; the velocity, already bounced, is scaled off the
    // starting walls' normals by beta, once.
    const starts = new ContactStarts(s);
    const touching = new Array(walls.length).fill(false);
    const before = new Float64Array(3);
    afterStep = () => {
      touching.fill(false);
      for (let link = ball.contactLink; link !== null; link = link.next) {
        if (!link.contact.touching) continue;
        const w = wallBodies.indexOf(link.body);
        if (w >= 0) touching[w] = true;
      }
      const axes = starts.starting(touching, before);
      if (axes.length > 0) {
        const v = starts.scaled([lv.x, lv.y, lv.z], axes);
        lv.set(v[0], v[1], v[2]);
      }
    };
    beforeStep = () => { before[0] = lv.x; before[1] = lv.y; before[2] = lv.z; };
  }

  // ---- Settings (each why: what Oimo's own value did, measured; docs/engines.md, Oimo) ----
  const add = (key, value, why) => settings.add(key, value, why);
  const mark = (value, key) => (value === OIMO[key] ? ' [Oimo\'s default]' : '');
  add('tangential_model', perContact ? `per-contact: beta = ${s.beta} once at each contact's start, after the step` : `friction: Coulomb mu = ${mu} (one coefficient: static = dynamic)`,
    perContact ? 'Oimo finds a wall contact only once the ball overlaps it and bounces it in that same step; the velocity is scaled after it (protocol ContactStarts); Oimo has no contact hook'
      : 'the scenario\'s [engines.<name>] friction');
  add('units_per_metre', U, 'Oimo hard-codes no bounce below 1 unit/s and a 0.005-unit overlap allowance (ContactConstraint.preSolve, lines 5371-5375): in metres (1) seed-3d never bounces: the back wall (t 0) and the x wall (1.517 s) stop the ball, it lands at 5.653 s and stays (highest 6-11 s: 0.0499 m against 0.4591 here)' + mark(U, 'units_per_metre'));
  add('restitution', `ball ${s.alpha}, walls ${wallRestitution}, geometric mean (hard-coded, Contact.mixRestitution)`,
    'both shapes carry alpha, so the mean is alpha; Oimo\'s default 0.2 on the walls gives sqrt(0.2 alpha) = 0.4 (seed-3d at 1e-3: highest 6-11 s 0.1539 m against 0.4591)' + mark(wallRestitution, 'wall_restitution'));
  add('friction', `ball ${mu}, walls ${wallFriction}, geometric mean (hard-coded, Contact.mixFriction)`,
    'both shapes carry mu; Oimo\'s default 0.2 on the walls gives sqrt(0.2 mu) (seed-3d friction mode at 1e-3, mu 0.005: 0.032; highest 6-11 s 0.4346 m against 0.4631)' + mark(wallFriction, 'wall_friction'));
  add('iterations', iterations, 'one contact point at a time: 1 iteration gives seed-3d bit for bit' + mark(iterations, 'iterations'));
  add('broadphase', broadphase, 'seven bodies: brute force gives seed-3d bit for bit' + mark(broadphase, 'broadphase'));
  add('randomizer', randomizer, 'shuffles the constraint order (a seeded LCG, deterministic); off gives seed-3d bit for bit' + mark(randomizer, 'randomizer'));
  add('sleeping', allowSleep ? 'Oimo\'s (below 0.2 units/s and 0.5 rad/s for 0.5 s)' : 'off (neverSleep)',
    'Oimo\'s default (World.callSleep, lines 11695-11700) is in units: in millimetres seed-3d is bit for bit the same; in metres the seed-3d ball sleeps mid-air from 2.016 s at z 0.6995 m, and a ball sliding at 0.02 m/s stops at 0.5 s');
  add('damping', 'none', 'Oimo has no linear or angular damping');
  add('ccd', 'none (contacts only while overlapping)', 'the ball overlaps a wall for one step at each impact, by up to its speed times dt');
  add('rotation', locked ? 'locked (zero inverse inertia)' : 'free', 'scenario [engines.<name>] rotation');
  add('gravity', `(${s.gravity.join(', ')}) m/s^2`, 'the scenario\'s, times units_per_metre');
  add('walls', `six static boxes ${thickness} m thick, inner faces on the walls`, 'boxes, as Oimo\'s own examples build floors');

  return {
    step() {
      if (afterStep) beforeStep();
      world.step();
      if (afterStep) afterStep();
    },
    read(out) {
      out[0] = pos.x / U; out[1] = pos.y / U; out[2] = pos.z / U;
      out[3] = lv.x / U; out[4] = lv.y / U; out[5] = lv.z / U;
    },
    free() { world.clear(); },
  };
}

export const adapter = {
  name: 'oimo',
  dimensions: [3],
  precision: 'f64',
  packages: () => ['oimo'],
  ownKeys,
  // build/oimo.js is the UMD build (CommonJS under Node); build/oimo.module.js
  // is ESM in a package that does not say so, which older Node refuses.
  async load() { return createRequire(import.meta.url)('oimo/build/oimo.js'); },
  version: (lib) => `Oimo.js ${lib.REVISION}`,
  build,
};

await serve(adapter);
