// nanohaptics play: the link to the server. One WebSocket (/ws): JSON text messages tagged by
// `type` (docs/play.md's table; crates/play/src/protocol.rs's ServerMsg and PageMsg), each
// handled by its entry in HANDLERS, and binary sound blocks for the sound module.

import { $, P, log, say } from './page.js';
import { aimAtWorkspace } from './camera.js';
import { onPcm } from './sound.js';

let ws = null;

// Sends a page message (an object with its `type`) if the link is open.
export function send(o) { if (ws && ws.readyState === 1) ws.send(JSON.stringify(o)); }

const WORDS = {
  'brick.grabbed': 'brick grabbed', 'brick.released': 'brick let go', 'brick.impact': 'impact',
  'brick.slot_filled': 'slot filled', 'brick.slot_emptied': 'slot emptied', 'button.down': 'button down',
  'button.up': 'button up', 'nano.snap': 'snap', 'nano.pull_off': 'pull-off', 'force.clamped': 'force at the limit',
  'switch.set': 'switch set', 'device.lost': 'hand lost', 'device.resumed': 'hand back',
};
// Every event is announced: those of half a second in one sentence, repeats counted, so a
// screen reader is not flooded.
const pending = new Map();
let lastAnnounce = 0;
function announceEvents(evs, now_) {
  for (const [, name] of evs) pending.set(name, (pending.get(name) || 0) + 1);
  const now = performance.now();
  if ((!now_ && now - lastAnnounce < 500) || pending.size === 0) return;
  lastAnnounce = now;
  const parts = [];
  for (const [name, c] of pending) parts.push((WORDS[name] || name.replace(/[._]/g, ' ')) + (c > 1 ? ` ×${c}` : ''));
  pending.clear();
  log(parts.join('; '));
}

// `hello`: the scene, the device, the menu; the Start button opens.
function onHello(h) {
  P.hello = h;
  $('title').textContent = h.scene;
  aimAtWorkspace(h);
  const menu = $('menu'); menu.textContent = '';
  for (const s of h.switches) {
    const lab = document.createElement('label');
    const span = document.createElement('span'); span.textContent = s.name; span.title = s.doc; lab.appendChild(span);
    const inp = document.createElement('input');
    if (s.boolean) { inp.type = 'checkbox'; inp.checked = s.value == null ? true : s.value !== 0; }
    else {
      inp.type = 'number'; inp.min = s.min; inp.max = s.max; inp.step = 'any'; inp.placeholder = `${s.min}–${s.max}`;
      if (s.value != null) inp.value = String(s.value);
    }
    inp.setAttribute('aria-label', `${s.name}: ${s.doc}`); inp.id = 'sw-' + s.name;
    const b = document.createElement('button'); b.type = 'button'; b.textContent = 'set';
    b.setAttribute('aria-label', `set ${s.name}`);
    b.addEventListener('click', () => {
      const v = s.boolean ? (inp.checked ? 1 : 0) : Number(inp.value);
      if (!s.boolean && (inp.value === '' || !Number.isFinite(v))) { say(`${s.name}: enter a number from ${s.min} to ${s.max}`); return; }
      send({ type: 'switch', name: s.name, value: v });
    });
    lab.appendChild(inp); lab.appendChild(b); menu.appendChild(lab);
  }
  const nb = h.buttons.length;
  $('turnkeys').textContent = nb > 1 ? `keys 1–${Math.min(3, nb - 1)}: ${h.buttons.slice(1, 4).join(', ')} (held)` : 'no turn buttons on this device';
  $('start-msg').textContent = h.page_is_hand
    ? `${h.scene}. Press Start: the page is the hand (pointer, keyboard or gamepad).`
    : `${h.scene}. A device is the hand; this page shows and sounds the session.`;
  $('go').disabled = false; $('go').focus();
}

// `frame`: the drawing (kept for the next animation frame), the events and sounds, the HUD.
let lastScore = null;
function onFrame(f) {
  P.frames++;
  if (f.prims) P.lastFrame = f;
  for (const e of f.events || []) P.events.push(e);
  for (const s of f.sounds || []) P.sounds.push(s);
  announceEvents(f.events || []);
  const st = f.state;
  if (st) {
    const sc = st.score;
    if (sc !== undefined) {
      $('score').textContent = sc.toFixed(0);
      if (lastScore !== null && Math.round(sc) !== Math.round(lastScore)) say(`score ${sc.toFixed(0)}`);
      lastScore = sc;
    }
    const lab = (f.prims || []).find((p) => p.k === 'label');
    if (lab) $('task').textContent = lab.text;
  }
  $('time').textContent = f.time_s.toFixed(1) + ' s';
  if (f.device_force_n && P.hello) $('force').value = Math.min(1, Math.hypot(...f.device_force_n) / P.hello.max_force_n);
}

// `end`: the session's figures and the recording's download.
function onEnd(m) {
  announceEvents([], true);
  P.ended = m;
  const rows = [['how it ended', m.end], ['time', `${m.seconds.toFixed(2)} s`], ['score', (m.state.score ?? 0).toFixed(1)]];
  for (const k of ['slots_filled', 'house_score', 'dropped', 'comfort_exceeded_s', 'complete_s']) {
    if (m.state[k] === undefined) continue;
    const v = k === 'complete_s' && m.state[k] < 0 ? 'not complete' : String(+m.state[k].toFixed(3));
    rows.push([k.replace(/_/g, ' '), v]);
  }
  rows.push(['peak force', `${m.peak_device_force_n.toFixed(2)} N`]);
  rows.push(['events', String(m.events)]);
  rows.push(['missed 1 ms deadlines', String(m.missed_deadlines)]);
  if (m.input_latency_ms) rows.push(['input → force p99', `${m.input_latency_ms.p99.toFixed(1)} ms`]);
  if (m.recording_bytes) rows.push(['recording', `${m.recording_file} (${(m.recording_bytes / 1024).toFixed(0)} KiB)`]);
  const t = $('figs'); t.textContent = '';
  for (const [k, v] of rows) { const tr = t.insertRow(); tr.insertCell().textContent = k; tr.insertCell().textContent = v; }
  $('download').setAttribute('download', m.recording_file || 'recording.mcap');
  $('end').classList.remove('hidden'); $('start').classList.add('hidden');
  say(`session over: score ${(m.state.score ?? 0).toFixed(0)}`);
  $('download').focus();
}

// One handler per server message type (a Map: no inherited keys). A type the page does not
// know is ignored, so an older page keeps working with a newer server.
const HANDLERS = new Map([
  ['hello', onHello],
  ['waiting', (m) => { $('start-msg').textContent = `Waiting for ${m.for}…`; }],
  ['role', (m) => { P.role = m.role; $('role').textContent = m.role === 'hand' ? 'the hand' : 'watching'; say(m.role === 'hand' ? 'you are the hand' : 'you are watching'); }],
  ['frame', onFrame],
  ['switched', (m) => { P.switched.push(m); say(`${m.name} set to ${m.value}`); }],
  ['error', (m) => { P.errors.push(m); say(m.message); }],
  ['end', onEnd],
]);

// Opens the link: text messages to their handlers, binary ones to the sound.
export function connect() {
  ws = new WebSocket(`ws://${location.host}/ws`);
  ws.binaryType = 'arraybuffer';
  ws.onmessage = (ev) => {
    if (typeof ev.data !== 'string') { onPcm(ev.data); return; }
    const m = JSON.parse(ev.data);
    const handle = HANDLERS.get(m.type);
    if (handle) handle(m);
  };
  ws.onclose = () => { if (!P.ended) say('the server closed the link'); };
}
