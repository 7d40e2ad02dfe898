// The one module every Node-hosted engine shares: protocol
// bouncecheck-external/1 (docs/external.md), in both of its modes, and the
// stepping loop. An engine file (engines/node/<name>.mjs) only loads its
// package and builds its world; this module reads the scenario, steps the
// world on the document's clock, writes the rows, times the engine's own
// steps for the `#end` line, and writes the settings.
//
//   node <name>.mjs              one scenario on stdin (read to its end)
//   node <name>.mjs --session    one scenario per line, each answered with
//                                header, rows and `#end`; the engine's
//                                package is loaded once for them all
//
// An engine file exports an object:
//   name          the simulator's name
//   dimensions    [2, 3], [3] or [2]
//   precision     "f32" or "f64": the engine's arithmetic
//   packages(d)   the npm packages the engine uses in dimension d
//   ownKeys       { key: "what it does" }: the [engines.<name>] keys it reads
//                 besides the shared ones (tangential_model, friction,
//                 rotation, substeps, ccd), each with ownKey below
//   load(d)       (async) the engine's module, loaded once per process and d
//   version(lib)  the engine's own version text, if it says one
//   build(lib, scenario, settings)
//                 the world for `scenario` (its dt already divided by
//                 substeps): { step(), read(out), free() }. read() fills a
//                 Float64Array(2 d) with the centre then the velocity, in
//                 the scenario's units. Every setting that changes the
//                 answer goes to settings.add(key, value, why).

import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

export const PROTOCOL = 1;
// Rows go out in binary blocks (`#f64 N`, docs/external.md, Output): text
// would cost more than a fast engine's step (the shortest round-trip text of
// seven doubles takes about 1.2 us in V8, and the harness parses it again).
const BLOCK_ROWS = 2048;
const MAX_LINE_BYTES = 1 << 20;   // a session's scenario line (a scenario is under 4 KB)
const SHARED_KEYS = new Set(['tangential_model', 'friction', 'rotation', 'substeps', 'ccd']);

const nodeFolder = path.dirname(path.dirname(fileURLToPath(import.meta.url)));

// The version npm installed of `name` (engines/node/node_modules, pinned by
// engines/node/package-lock.json).
const versions = new Map();  // read once per process, not once per scenario
export function packageVersion(name) {
  if (!versions.has(name)) {
    const file = path.join(nodeFolder, 'node_modules', name, 'package.json');
    versions.set(name, JSON.parse(fs.readFileSync(file, 'utf8')).version);
  }
  return versions.get(name);
}

// A failure the harness shows as the row's reason: its last stderr lines.
export class ScenarioError extends Error {}

// The settings of one run, written to the harness's settings file.
export class Settings {
  constructor() { this.list = []; }
  add(key, value, why = '') { this.list.push({ key, value, why }); }
}

// ---- What the law and the room give every adapter (as engines/engine.h) ----

// The room's walls: the plane x[axis] = offset, side -1 (lower) or +1 (upper).
export function roomWalls(s) {
  const walls = [];
  for (let axis = 0; axis < s.dimension; ++axis) {
    walls.push({ axis, side: -1, offset: 0 });
    walls.push({ axis, side: +1, offset: s.room[axis] });
  }
  return walls;
}

// The fastest the ball can ever move: its start speed plus the whole room to
// fall along every axis (the law never adds energy).
export function maxBallSpeed(s) {
  let v2 = 0;
  for (let i = 0; i < s.dimension; ++i) v2 += s.velocity[i] ** 2 + 2 * Math.abs(s.gravity[i]) * s.room[i];
  return Math.sqrt(v2);
}

// The law's contact condition at a wall the ball has just started touching:
// it moves into the wall, or rests against it while gravity presses it in.
export function movesIntoWall(normalVelocity, normalGravity, side) {
  return normalVelocity * side > 0 || (normalVelocity === 0 && normalGravity * side > 0);
}

// Per-contact mode for an engine whose hook fires after its step (or that
// has none): `touching` is, per wall of roomWalls(s), whether the engine
// holds a contact with it after this step. A wall touched now and not
// before starts a contact; if the ball was moving into it at the start of
// the step (`before`, the velocity then), every velocity component normal
// to none of the starting walls is scaled by beta, once. Returns the
// scaled velocity, or null if no contact started.
export class ContactStarts {
  constructor(s) {
    this.s = s;
    this.walls = roomWalls(s);
    this.was = new Array(this.walls.length).fill(false);
  }
  // Which walls start a contact the law counts, given this step's touching.
  starting(touching, before) {
    const axes = [];
    for (let w = 0; w < this.walls.length; ++w) {
      const { axis, side } = this.walls[w];
      if (touching[w] && !this.was[w] && movesIntoWall(before[axis], this.s.gravity[axis], side)) axes.push(axis);
      this.was[w] = touching[w];
    }
    return axes;
  }
  // `velocity` with every component off the `axes` scaled by beta.
  scaled(velocity, axes) {
    const out = Array.from(velocity);
    for (let i = 0; i < this.s.dimension; ++i) if (!axes.includes(i)) out[i] *= this.s.beta;
    return out;
  }
}

// Per-contact mode after the step, for an engine whose contacts begin before
// the impact (speculative contacts) and may outlive it: a wall contact the
// engine starts while the ball moves into the wall (or rests on it, pressed by
// gravity) arms that wall; so does a new approach within a contact the engine
// kept (the ball moved away from the wall faster than a step of gravity, then
// back into it: a bounce lower than the engine's contact margin). The law's
// contact is the step in which the ball then stops moving into the wall (the
// engine turned it), and only then are the other components scaled by beta,
// once. A contact that ends unturned (a near miss) is dropped. So beta lands in
// the step in which the engine bounces the ball, where the harness measures it
// (ContactStarts above scales at the contact's start, which here comes
// up to a few steps early, and never again while the engine keeps the contact).
export class TurnedContacts {
  constructor(s) {
    this.s = s;
    this.walls = roomWalls(s);
    this.was = new Array(this.walls.length).fill(false);
    this.armed = new Array(this.walls.length).fill(false);
    this.away = new Array(this.walls.length).fill(false);
    this.eps = Math.hypot(...s.gravity) * s.dt;  // a step of gravity
    this.axes = [];
  }
  // `touching`: per wall, whether the engine holds a contact after this step;
  // `before`, `after`: the ball's velocity at the step's start and end. Returns
  // the axes whose walls count a contact in this step (empty: none).
  turned(touching, before, after) {
    const axes = this.axes;
    axes.length = 0;
    for (let w = 0; w < this.walls.length; ++w) {
      const { axis, side } = this.walls[w];
      if (touching[w] && (!this.was[w] || this.away[w]) && movesIntoWall(before[axis], this.s.gravity[axis], side)) {
        this.armed[w] = true;
        this.away[w] = false;
      }
      this.was[w] = touching[w];
      if (!touching[w]) { this.armed[w] = false; this.away[w] = false; continue; }
      if (after[axis] * side < -this.eps) this.away[w] = true;
      if (this.armed[w] && !(after[axis] * side > 0)) { this.armed[w] = false; axes.push(axis); }
    }
    return axes;
  }
}

// ---- The scenario and the [engines.<name>] table ----

function fail(message) { throw new ScenarioError(message); }

// The scenario as the harness wrote it, with `engine` holding the shared
// options (defaults filled in) and the engine's own keys. An unknown key
// fails the run: a typo must not silently leave a default in place.
function readScenario(text, adapter) {
  let s;
  try { s = JSON.parse(text); } catch (e) { fail(`the scenario is not JSON: ${e.message}`); }
  if (!s || typeof s !== 'object' || s.protocol !== PROTOCOL) fail('expected a JSON object with "protocol": 1');
  if (!adapter.dimensions.includes(s.dimension)) fail(`${adapter.name} cannot run a ${s.dimension}D scenario`);
  const given = s.engine && typeof s.engine === 'object' ? s.engine : {};
  for (const key of Object.keys(given))
    if (!SHARED_KEYS.has(key) && !Object.hasOwn(adapter.ownKeys, key))  // not "constructor", "toString"...
      fail(`[engines.${adapter.name}] has no key "${key}" (its own keys: ${Object.keys(adapter.ownKeys).join(', ') || 'none'})`);
  const engine = { tangential_model: 'friction', friction: 0, rotation: 'free', substeps: 1, ...given };
  const where = `[engines.${adapter.name}]`;
  if (!Number.isInteger(engine.substeps) || engine.substeps < 1) fail(`${where} substeps must be an integer >= 1`);
  if (engine.tangential_model !== 'friction' && engine.tangential_model !== 'per-contact')
    fail(`${where} tangential_model must be "friction" or "per-contact", got ${JSON.stringify(engine.tangential_model)}`);
  if (engine.rotation !== 'free' && engine.rotation !== 'locked')
    fail(`${where} rotation must be "free" or "locked", got ${JSON.stringify(engine.rotation)}`);
  if (typeof engine.friction !== 'number' || !Number.isFinite(engine.friction) || engine.friction < 0)
    fail(`${where} friction must be a number >= 0`);
  if (engine.tangential_model === 'per-contact' && engine.friction !== 0)
    fail(`${where} friction applies only with tangential_model = "friction" (per-contact runs with mu = 0)`);
  if (engine.ccd !== undefined && typeof engine.ccd !== 'boolean') fail(`${where} ccd must be true or false`);
  // engineName: the adapter's name, for ownKey's messages ([engines.<name>]),
  // so that no engine file writes its own name into them.
  return { ...s, engine, engineName: adapter.name };
}

// One of the engine's own keys, `[engines.<name>] <key>`: `chosen` (the
// adapter's default) when the key is not in the table, else the value given,
// which must pass `kind`, a pair [check, what]: a predicate and the text of
// what it asks for. Every engine file reads its own keys through this one
// function, so they are all checked alike and fail with the same message:
//   [engines.<name>] <key> must be <what> (got <the value as JSON>)
export function ownKey(s, key, chosen, [check, what]) {
  if (!Object.hasOwn(s.engine, key)) return chosen;
  const given = s.engine[key];
  if (!check(given)) fail(`[engines.${s.engineName}] ${key} must be ${what} (got ${JSON.stringify(given)})`);
  return given;
}

// Kinds for ownKey. A number is a finite one (JSON's 1e999 parses to Infinity).
const isNumber = (x) => typeof x === 'number' && Number.isFinite(x);
export const aNumber = [isNumber, 'a number'];
export const aNumberAtLeast = (min) => [(x) => isNumber(x) && x >= min, `a number >= ${min}`];
export const aNumberAbove = (min) => [(x) => isNumber(x) && x > min, `a number > ${min}`];
export const anIntegerAtLeast = (min) => [(x) => Number.isInteger(x) && x >= min, `an integer >= ${min}`];
export const anIntegerIn = (min, max) => [(x) => Number.isInteger(x) && x >= min && x <= max, `an integer ${min}..${max}`];
export const nonNegative = aNumberAtLeast(0);    // a number >= 0
export const positive = aNumberAbove(0);         // a number > 0
// Counts stop at int32's largest: the WebAssembly engines take them as 32-bit
// integers, where 2^32 would wrap to 0.
export const count0 = anIntegerIn(0, 2 ** 31 - 1);
export const count1 = anIntegerIn(1, 2 ** 31 - 1);
export const trueOrFalse = [(x) => typeof x === 'boolean', 'true or false'];
// One of the given values (compared with ===): "PGS" or "TGS"; "auto", 1, 3, 4 or 6.
export function oneOf(...values) {
  const shown = values.map((v) => JSON.stringify(v));
  const what = shown.length > 1 ? `${shown.slice(0, -1).join(', ')} or ${shown.at(-1)}` : shown[0];
  return [(x) => values.includes(x), what];
}
// An array of n values, each passing `kind`'s check: listOf(2, anIntegerIn(1, 255), '[position, velocity], integers 1..255').
export const listOf = (n, [check], what) => [(x) => Array.isArray(x) && x.length === n && x.every((v) => check(v)), what];
const WORDS = ['no', 'one', 'two', 'three', 'four', 'five', 'six', 'seven', 'eight', 'nine'];
export const numbers = (n) => listOf(n, aNumber, `${WORDS[n] ?? n} numbers`);
// Any of the kinds: either(oneOf('auto'), positive) is "auto" or a number > 0.
export const either = (...kinds) => [(x) => kinds.some(([check]) => check(x)), kinds.map(([, what]) => what).join(' or ')];

// ---- The run ----

function writeAll(textOrBytes) {
  const bytes = typeof textOrBytes === 'string' ? Buffer.from(textOrBytes) : textOrBytes;
  let done = 0;
  while (done < bytes.length) {
    try { done += fs.writeSync(1, bytes, done); } catch (e) { if (e.code !== 'EAGAIN') throw e; }
  }
}

// A short throwaway run right after the load, so that V8 has compiled the
// engine's WebAssembly to its optimising tier before any step is timed: the
// first thousand steps of a fresh module cost 5-250 us each (warm-up), which
// is start-up, not the engine's step. It bounces a ball in both modes.
const WARM_UP_STEPS = 2000;
function warmUp(adapter, lib, dimension) {
  const vertical = dimension - 1;
  const vector = (values) => values.slice(0, dimension);
  for (const tangential_model of ['per-contact', 'friction']) {
    const gravity = new Array(dimension).fill(0);
    gravity[vertical] = -9.81;
    const s = {
      protocol: PROTOCOL, scenario: 'warm-up', dimension, room: new Array(dimension).fill(1), radius: 0.05,
      position: vector([0.3, 0.4, 0.5]), velocity: vector([1.5, -1, 0.5]), gravity, alpha: 0.8, beta: 0.99,
      dt: 1e-3, duration: WARM_UP_STEPS * 1e-3, steps: WARM_UP_STEPS,
      engine: { tangential_model, friction: tangential_model === 'friction' ? 0.1 : 0, rotation: 'free', substeps: 1 },
      engineName: adapter.name,
    };
    const world = adapter.build(lib, s, new Settings());
    try {
      const state = new Float64Array(2 * dimension);
      for (let k = 0; k < WARM_UP_STEPS / 2; ++k) { world.step(); world.read(state); }
    } finally {
      world.free?.();
    }
  }
}

const loaded = new Map();  // dimension -> the engine's module, loaded once per process
async function libraryFor(adapter, dimension) {
  if (!loaded.has(dimension)) {
    const lib = await adapter.load(dimension);
    warmUp(adapter, lib, dimension);
    loaded.set(dimension, lib);
  }
  return loaded.get(dimension);
}

async function runScenario(adapter, text) {
  if (os.endianness() !== 'LE') fail('the rows are written as little-endian binary64 (docs/external.md): this machine is big-endian');
  const s = readScenario(text, adapter);
  const lib = await libraryFor(adapter, s.dimension);
  const d = s.dimension;
  const substeps = s.engine.substeps;
  const settings = new Settings();
  const packages = adapter.packages(d).map((p) => `${p} ${packageVersion(p)}`).join(', ');
  const own = adapter.version ? adapter.version(lib, d) : '';
  settings.add('engine', own ? `${own} (${packages})` : packages, 'the npm package that stepped the run (engines/node/package-lock.json)');
  settings.add('precision', adapter.precision, adapter.precision === 'f32' ? 'the WebAssembly build computes in 32-bit floats' : '64-bit floats');
  settings.add('runtime', `Node ${process.versions.node}`, 'the host that ran the engine');
  settings.add('substeps', `${substeps} engine step${substeps === 1 ? '' : 's'} of ${s.dt / substeps} s per scenario step`,
    substeps === 1 ? "one engine step per scenario step (the document's step)"
      : 'scenario [engines.<name>] substeps: shorter engine steps against fast balls and large dt');
  const world = adapter.build(lib, { ...s, dt: s.dt / substeps }, settings);
  try {
    const state = new Float64Array(2 * d);
    writeAll(d === 3 ? 't,x,y,z,vx,vy,vz\n' : 't,x,y,vx,vy\n');
    // Each row: t, the centre, the velocity, as binary64 in this machine's
    // order, which runScenario checked is little-endian (a typed array's stores
    // cost half a DataView's here).
    const width = 1 + 2 * d;
    const block = new Float64Array(BLOCK_ROWS * width);
    const blockBytes = Buffer.from(block.buffer);
    let at = 0;
    const flush = () => {
      writeAll(`#f64 ${at / width}\n`);
      writeAll(blockBytes.subarray(0, at * 8));
      at = 0;
    };
    const put = (time, values) => {
      block[at] = time;
      for (let i = 0; i < 2 * d; ++i) block[at + 1 + i] = values[i];
      at += width;
      if (at === block.length) flush();
    };
    put(0, [...s.position, ...s.velocity]);
    let t = 0;
    let stepNanoseconds = 0n;
    const loopStart = process.hrtime.bigint();
    const dt = s.dt, steps = s.steps;
    for (let k = 0; k < steps; ++k) {
      const start = process.hrtime.bigint();
      for (let i = 0; i < substeps; ++i) world.step();
      stepNanoseconds += process.hrtime.bigint() - start;
      world.read(state);
      t += dt;  // the document's clock: partial sums of dt
      put(t, state);
    }
    const loopSeconds = Number(process.hrtime.bigint() - loopStart) / 1e9;
    // The settings file first: the harness reads it once it has read `#end`.
    fs.writeFileSync(s.settings_file, JSON.stringify(settings.list));
    if (at) flush();
    writeAll(`#end ${JSON.stringify({ step_seconds: Number(stepNanoseconds) / 1e9, loop_seconds: loopSeconds })}\n`);
  } finally {
    world.free?.();
  }
}

// Reads fd 0 line by line, blocking: a session's scenarios arrive one per line.
function* lines() {
  const buffer = Buffer.alloc(1 << 16);
  let pending = Buffer.alloc(0);
  for (;;) {
    let n;
    try { n = fs.readSync(0, buffer, 0, buffer.length, null); } catch (e) {
      if (e.code === 'EAGAIN') continue;
      if (e.code === 'EOF') n = 0; else throw e;
    }
    if (n === 0) { if (pending.length) yield pending.toString('utf8'); return; }
    pending = Buffer.concat([pending, buffer.subarray(0, n)]);
    let newline;
    while ((newline = pending.indexOf(10)) >= 0) {
      yield pending.subarray(0, newline).toString('utf8');
      pending = pending.subarray(newline + 1);
    }
    if (pending.length > MAX_LINE_BYTES) fail(`a scenario line longer than ${MAX_LINE_BYTES} bytes`);
  }
}

// What the engine file is, for the harness's tests: its name, dimensions,
// precision, packages with their installed versions, and own keys.
function describe(adapter) {
  const packages = {};
  for (const d of adapter.dimensions) packages[d] = adapter.packages(d).map((p) => `${p} ${packageVersion(p)}`);
  return JSON.stringify({ name: adapter.name, dimensions: adapter.dimensions, precision: adapter.precision,
    packages, ownKeys: Object.keys(adapter.ownKeys) });
}

// The entry point of every engine file: `await serve(adapter)`.
export async function serve(adapter) {
  try {
    if (process.argv.includes('--describe')) {
      writeAll(describe(adapter) + '\n');
    } else if (process.argv.includes('--session')) {
      for (const line of lines()) if (line.trim()) await runScenario(adapter, line);
    } else {
      await runScenario(adapter, fs.readFileSync(0, 'utf8'));
    }
  } catch (e) {
    process.stderr.write(`${adapter.name}: ${e instanceof ScenarioError ? e.message : e.stack || e}\n`);
    process.exitCode = 1;
  }
}
