// nanohaptics replay: a recording in the browser. The server re-simulated the session from the
// recording into the frames a live page is sent (crates/play/src/replay/); this page fetches
// them in chunks, draws the one at the timeline's time with the game's own drawing (draw.js),
// says the events it passes (events.js) and plays the sound track (render --audio's samples).
// window.__replay holds figures for tests.

import { $, P, log, say } from './page.js';
import { resize, aimAtWorkspace } from './camera.js';
import { draw } from './draw.js';
import { sentence } from './events.js';

const CHUNK = 500;
const R = (window.__replay = {
  index: null, hello: null, tick: 0, playing: false, speed: 1, ready: false,
  drawn: null, said: [], errors: [],
  sound: { samples: 0, hash: null, starts: 0 },
});
const chunks = new Map();
let buffer = null, ctx = null, source = null;
let frames = 0, rate = 1000, lastTick = 0;
let clock = { t0: 0, tick0: 0 };
let shown = -1;

function fail(e) { R.errors.push(String(e)); say(`replay error: ${e}`); }

// A data path with the page's own query (a class's replay names the student and carries the
// teacher's code) and `params`.
function api(path, params = {}) {
  const q = new URLSearchParams(location.search);
  for (const [k, v] of Object.entries(params)) q.set(k, String(v));
  const s = q.toString();
  return s ? `${path}?${s}` : path;
}

async function getJSON(url) {
  const r = await fetch(url);
  if (!r.ok) throw new Error(`${url}: ${r.status} ${await r.text()}`);
  return r.json();
}

function chunk(c) {
  if (!chunks.has(c)) chunks.set(c, getJSON(api('/replay/frames.json', { from: c * CHUNK, count: CHUNK })));
  return chunks.get(c);
}

// The index of the frame drawn at `tick`: the last frame at or before it.
function frameIndex(tick) {
  const ft = R.index.frame_ticks;
  let lo = 0, hi = ft.length;
  while (lo < hi) { const m = (lo + hi) >> 1; if (ft[m] <= tick) lo = m + 1; else hi = m; }
  return Math.max(0, lo - 1);
}

async function frame(i) {
  const c = Math.floor(i / CHUNK);
  const list = await chunk(c);
  if ((c + 1) * CHUNK < frames) chunk(c + 1);
  return list[i - c * CHUNK];
}

// FNV-1a over the samples' Float32 little-endian bytes (the tests' hash of render --audio).
function fnv1a(f32) {
  const b = new Uint8Array(f32.buffer, f32.byteOffset, f32.byteLength);
  let h = 0x811c9dc5;
  for (let i = 0; i < b.length; i++) { h ^= b[i]; h = Math.imul(h, 0x01000193) >>> 0; }
  return h >>> 0;
}

function fmt(t) { return `${t.toFixed(3)} s`; }

// Shows tick `tick`: the frame at or before it, the time, the force; with `say`, the events
// of the frames passed since the last one shown (playing forward), in words.
async function show(tick, sayEvents) {
  R.tick = tick;
  $('timeline').value = String(tick);
  $('time').textContent = fmt(tick / rate);
  $('timeline').setAttribute('aria-valuetext', fmt(tick / rate));
  const i = frameIndex(tick);
  if (i === shown) return;
  const from = shown;
  shown = i;
  const f = await frame(i);
  if (shown !== i) return;
  if (sayEvents && from >= 0 && i > from) {
    for (let k = from + 1; k <= i; k++) {
      const fk = await frame(k);
      for (const [t, name, detail] of fk.events) {
        const s = sentence(name, detail, R.hello);
        if (s !== null) { R.said.push([t, s]); log(`${fmt(t / rate)}: ${s}`); }
      }
    }
  }
  if (f.prims) {
    R.drawn = { tick: f.tick, prims: f.prims, cursor_m: f.cursor_m, world_force_n: f.world_force_n };
    const fn = f.world_force_n;
    $('force').textContent = `${Math.hypot(fn[0], fn[1], fn[2]).toFixed(2)} N`;
    P.lastFrame = f;
  }
}

function stopSound() {
  if (source) { try { source.stop(); } catch (e) { /* already stopped */ } source = null; }
}

function startSound() {
  stopSound();
  if (!ctx || !buffer) return;
  source = ctx.createBufferSource();
  source.buffer = buffer;
  source.playbackRate.value = R.speed;
  source.connect(ctx.destination);
  source.start(0, Math.min(R.tick / rate, buffer.duration));
  R.sound.starts++;
}

function setPlaying(on) {
  if (!R.ready) return;
  if (on && R.tick >= lastTick) R.tick = 0;
  R.playing = on;
  $('play').textContent = on ? 'Pause' : 'Play';
  $('play').setAttribute('aria-label', on ? 'pause' : 'play');
  clock = { t0: performance.now(), tick0: R.tick };
  if (on) {
    if (!ctx) { ctx = new AudioContext({ latencyHint: 'interactive' }); makeBuffer(); }
    startSound();
  } else stopSound();
}

function seek(tick) {
  const t = Math.max(0, Math.min(lastTick, Math.round(tick)));
  clock = { t0: performance.now(), tick0: t };
  shown = -1;
  show(t, false).catch(fail);
  if (R.playing) startSound();
}

function setSpeed(s) {
  R.speed = s;
  $('speed').value = String(s);
  clock = { t0: performance.now(), tick0: R.tick };
  if (R.playing) startSound();
}

let samples = null;
function makeBuffer() {
  if (!ctx || !samples || buffer) return;
  buffer = ctx.createBuffer(1, Math.max(1, samples.length), R.index.sample_rate_hz);
  buffer.copyToChannel(samples, 0);
  R.sound.hash = fnv1a(buffer.getChannelData(0).subarray(0, samples.length));
}

function loop(t) {
  if (R.playing) {
    const tick = Math.min(lastTick, clock.tick0 + Math.floor((t - clock.t0) / 1000 * rate * R.speed));
    show(tick, true).catch(fail);
    if (tick >= lastTick) setPlaying(false);
  }
  draw(P.lastFrame, R.hello, false);
  requestAnimationFrame(loop);
}

const SPEEDS = [0.25, 0.5, 1, 2, 4];
function installControls() {
  $('play').addEventListener('click', () => setPlaying(!R.playing));
  $('speed').addEventListener('change', () => setSpeed(Number($('speed').value)));
  $('timeline').addEventListener('input', () => seek(Number($('timeline').value)));
  window.addEventListener('keydown', (e) => {
    // A focused button takes its own Space; a select and the timeline their own keys.
    const tag = e.target && e.target.tagName;
    if (tag === 'BUTTON' && e.key === ' ') return;
    if (tag === 'SELECT' || (tag === 'INPUT' && e.key !== ' ' && e.key !== 'k')) return;
    if (e.key === ' ' || e.key === 'k') { e.preventDefault(); setPlaying(!R.playing); }
    else if (e.key === ',' || e.key === '.') {
      const i = frameIndex(R.tick) + (e.key === '.' ? 1 : -1);
      const ft = R.index.frame_ticks;
      seek(ft[Math.max(0, Math.min(ft.length - 1, i))]);
    } else if (e.key === '[' || e.key === ']') {
      const k = SPEEDS.indexOf(R.speed) + (e.key === ']' ? 1 : -1);
      setSpeed(SPEEDS[Math.max(0, Math.min(SPEEDS.length - 1, k))]);
    }
  });
}

async function start() {
  window.addEventListener('resize', resize);
  resize();
  installControls();
  const [index, hello] = await Promise.all([getJSON(api('/replay/index.json')), getJSON(api('/replay/hello.json'))]);
  R.index = index;
  R.hello = hello;
  P.hello = hello;
  rate = index.rate_hz;
  frames = index.frame_ticks.length;
  lastTick = Math.max(0, index.ticks - 1);
  aimAtWorkspace(hello);
  $('title').textContent = `replay: ${hello.scene}`;
  document.title = `nanohaptics replay: ${hello.scene}`;
  $('length').textContent = `/ ${fmt(index.ticks / rate)}`;
  const tl = $('timeline');
  tl.max = String(lastTick);
  tl.setAttribute('aria-valuetext', '0 s');
  $('download').href = api('/recording.mcap');
  const r = await fetch(api('/replay/sound.f32'));
  if (!r.ok) throw new Error(`/replay/sound.f32: ${r.status}`);
  samples = new Float32Array(await r.arrayBuffer());
  R.sound.samples = samples.length;
  await show(0, false);
  tl.disabled = false;
  $('play').disabled = false;
  R.ready = true;
  say(`${hello.scene}: ${fmt(index.ticks / rate)} recorded. Press Space to play.`);
  requestAnimationFrame(loop);
}

start().catch(fail);
