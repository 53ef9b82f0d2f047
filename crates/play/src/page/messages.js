// nanohaptics play: the link to the server. One WebSocket (`/ws` and the page's own query),
// owned by a dedicated Worker (link.js), which sends the binary sound ticks straight to the
// synthesis and passes the JSON text messages on to this thread: each tagged by `type`
// (docs/play.md's table; crates/play/src/protocol/'s ServerMsg and PageMsg) and handled by its
// entry in HANDLERS. The events' words are events.js's.

import { $, P, log, say } from './page.js';
import { aimAtWorkspace } from './camera.js';
import { onLinkReport } from './sound.js';
import { eventClass, sentence } from './events.js';
import { lessonRuns, onLesson } from './lesson.js';

const LINK_URL = new URL('./link.js', import.meta.url);
let link = null;

// Sends a page message (an object with its `type`) if the link is open.
export function send(o) { if (link) link.postMessage({ send: JSON.stringify(o) }); }

// A message to the link worker (`transfer`: the objects it takes over, a MessagePort).
export function toLink(m, transfer) { if (link) link.postMessage(m, transfer || []); }
// The events of a frame, in words (events.js classes them): the game's events of half a
// second in one sentence, repeats counted ("grabbed brick 1; slot 1 filled with brick 1"),
// so a screen reader is not flooded; the grip at once. The loop's timing, safety and device
// reports are never said: they stay in the recording and the end summary.
const pending = new Map();
let lastAnnounce = 0;
function announceEvents(evs, flush) {
  for (const [, name, detail] of evs) {
    const s = sentence(name, detail, P.hello);
    if (s === null) continue;
    if (eventClass(name) === 'now') say(s);
    else pending.set(s, (pending.get(s) || 0) + 1);
  }
  const now = performance.now();
  if ((!flush && now - lastAnnounce < 500) || pending.size === 0) return;
  lastAnnounce = now;
  const parts = [];
  for (const [s, c] of pending) parts.push(c > 1 ? `${s} ×${c}` : s);
  pending.clear();
  log(parts.join('; '));
}

// A switch's value in words: on/off for a boolean switch, else the number (6 digits at most).
function valueText(s, v) {
  if (v === null || v === undefined || !Number.isFinite(v)) return 'not known';
  if (s.boolean) return v !== 0 ? 'on' : 'off';
  return String(+v.toPrecision(6));
}
// The menu's switches by name: the hello's entry, its input and its value line.
const menuRows = new Map();
// Shows switch `name`'s value now (from the hello, then from each `switched`); the input
// takes it too unless the player is typing in it.
function showSwitch(name, v) {
  const row = menuRows.get(name);
  if (!row) return;
  const { s, inp, now } = row;
  now.textContent = `now ${valueText(s, v)} · ${s.boolean ? 'on or off' : `allowed ${valueText(s, s.min)} to ${valueText(s, s.max)}`}`;
  if (document.activeElement !== inp && v !== null && v !== undefined) {
    if (s.boolean) inp.checked = v !== 0;
    else inp.value = String(v);
  }
  P.menu[name] = v;
}

// `hello`: the scene, the device, the menu; the Start button opens.
function onHello(h) {
  // A lesson's next world: the link (route.js) has restarted the sound's stream at tick 0.
  P.hello = h;
  $('title').textContent = h.scene;
  aimAtWorkspace(h);
  const menu = $('menu'); menu.textContent = ''; menuRows.clear(); P.menu = {};
  for (const s of h.switches) {
    const lab = document.createElement('label');
    const span = document.createElement('span'); span.textContent = s.name; span.title = s.doc; lab.appendChild(span);
    const inp = document.createElement('input');
    if (s.boolean) { inp.type = 'checkbox'; inp.checked = true; } // on unless the hello says
    else { inp.type = 'number'; inp.min = s.min; inp.max = s.max; inp.step = 'any'; inp.placeholder = `${s.min}–${s.max}`; }
    inp.setAttribute('aria-label', `${s.name}: ${s.doc}`); inp.id = 'sw-' + s.name;
    const b = document.createElement('button'); b.type = 'button'; b.textContent = 'set';
    b.setAttribute('aria-label', `set ${s.name}`);
    b.addEventListener('click', () => {
      const v = s.boolean ? (inp.checked ? 1 : 0) : Number(inp.value);
      if (!s.boolean && (inp.value === '' || !Number.isFinite(v))) { say(`${s.name}: enter a number from ${s.min} to ${s.max}`); return; }
      send({ type: 'switch', name: s.name, value: v });
    });
    // The value now and the range, beside the input (the input's description).
    const now = document.createElement('output'); now.className = 'now'; now.id = 'now-' + s.name;
    inp.setAttribute('aria-describedby', now.id);
    lab.appendChild(inp); lab.appendChild(b); lab.appendChild(now); menu.appendChild(lab);
    menuRows.set(s.name, { s, inp, now });
    showSwitch(s.name, s.value);
  }
  const nb = h.buttons.length;
  $('turnkeys').textContent = nb > 1 ? `keys 1–${Math.min(3, nb - 1)}: ${h.buttons.slice(1, 4).join(', ')} (held)` : 'no turn buttons on this device';
  $('start-msg').textContent = h.page_is_hand
    ? `${h.scene}. Press Start: the page is the hand (pointer, keyboard or gamepad).`
    : `${h.scene}. A device is the hand; this page shows and sounds the session.`;
  $('go').disabled = false;
  // In a lesson the page stays the hand from one step's world to the next.
  if (lessonRuns() && P.role === 'hand') { $('start').classList.add('hidden'); return; }
  if (lessonRuns()) $('start').classList.remove('hidden');
  $('go').focus();
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
  // In a lesson a step's world completed, not the page's session: the next `lesson` message
  // says what follows (the hand goes on into the next step's world). A stopped world (E,
  // Ctrl-C) ends the lesson there, with the end screen.
  // The link (route.js) has finished the sound's stream, in the same order.
  if (lessonRuns() && m.end === 'completed') { P.stepEnds.push(m); return; }
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
  // The recording's link is the one the server names (its path depends on the server).
  if (m.recording) $('download').setAttribute('href', m.recording);
  $('download').setAttribute('download', m.recording_file || 'recording.mcap');
  $('end').classList.remove('hidden'); $('start').classList.add('hidden');
  say(`session over: score ${(m.state.score ?? 0).toFixed(0)}`);
  $('download').focus();
}

// `switched`: a switch applied (set by this page, another page or the teacher): the menu
// shows its value now.
function onSwitched(m) {
  P.switched.push(m);
  showSwitch(m.name, m.value);
  const row = menuRows.get(m.name);
  say(`${m.name} set to ${row ? valueText(row.s, m.value) : m.value}`);
}

// One handler per server message type (a Map: no inherited keys). A type the page does not
// know is ignored, so an older page keeps working with a newer server.
const HANDLERS = new Map([
  ['hello', onHello],
  ['waiting', (m) => { $('start-msg').textContent = `Waiting for ${m.for}…`; }],
  ['role', (m) => { P.role = m.role; $('role').textContent = m.role === 'hand' ? 'the hand' : 'watching'; say(m.role === 'hand' ? 'you are the hand' : 'you are watching'); }],
  ['frame', onFrame],
  ['switched', onSwitched],
  ['error', (m) => { P.errors.push(m); say(m.message); }],
  ['end', onEnd],
  ['lesson', onLesson],
]);

// Opens the link: the worker opens the socket; text messages come back to their handlers, the
// link's reports (the sound's counts) to the sound module.
export function connect() {
  // `/ws` with the page's own query (a classroom's `?s=TOKEN` comes back with the link).
  const scheme = location.protocol === 'https:' ? 'wss' : 'ws';
  try {
    link = new Worker(LINK_URL, { type: 'module' });
  } catch (err) { say('this browser cannot open the link to the server'); return; }
  link.onmessage = (e) => {
    const d = e.data;
    if (typeof d === 'string') {
      const m = JSON.parse(d);
      const handle = HANDLERS.get(m.type);
      if (handle) handle(m);
    } else if (d.closed) { if (!P.ended) say('the server closed the link'); }
    else onLinkReport(d);
  };
  link.onerror = () => say('the link to the server failed to load');
  link.postMessage({ open: `${scheme}://${location.host}/ws${location.search}` });
}
