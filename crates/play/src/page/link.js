// nanohaptics play: the link to the server, a dedicated Worker (messages.js starts it with
// `new Worker(url, { type: 'module' })`), so that the page's drawing never holds up the sound.
// It owns the page's one WebSocket (`/ws` and the page's own query). Its route (route.js)
// sends the binary sound ticks straight to the synthesis (synth.js) through the MessagePort
// the page gives it, with a lesson's restarts and each end in the same order; the text
// messages go to the page's main thread as they came (the string: messages.js parses and
// handles it). The counts the tests and benches read go to the page every 100 ms, and before
// the hello, end and lesson messages (so they are there when those are handled).
//
// From the page: `{ open: URL }` opens the socket; `{ send: TEXT }` sends a page message (not
// when the socket is not open); `{ audio: 'on' | 'none' }` the audio opened, or there is none;
// `{ port }` the synthesis's port, or `{ ring }` its ring (a SharedArrayBuffer, route.js's
// SoundRing; on a cross-origin isolated page). To the page: a text message (a string); `{ counts }` the
// route's report; `{ stamp: MS }` the wall time of a tick with a sound, when the link passes
// it on (the page times tick → its main thread from it); `{ closed: true }` the server
// closed the link.

import { SoundRoute } from './route.js';

const route = new SoundRoute();
let ws = null;

// The counts to the page, if any changed.
function report() {
  const r = route.report();
  if (r !== null) postMessage({ counts: r });
}

function open(url) {
  ws = new WebSocket(url);
  ws.binaryType = 'arraybuffer';
  ws.onmessage = (ev) => {
    if (typeof ev.data !== 'string') {
      const stamp = route.binary(ev.data, Date.now());
      if (stamp !== null) postMessage({ stamp });
      return;
    }
    if (route.text(ev.data)) report();
    postMessage(ev.data);
  };
  ws.onclose = () => { report(); postMessage({ closed: true }); };
}

self.onmessage = (e) => {
  const m = e.data;
  if (typeof m.send === 'string') { if (ws && ws.readyState === 1) ws.send(m.send); }
  else if (m.port) route.connect(m.port);
  else if (m.ring) route.connectRing(m.ring);
  else if (m.audio === 'on') route.audioOn();
  else if (m.audio === 'none') route.audioNone();
  else if (typeof m.open === 'string' && ws === null) open(m.open);
};

// The counts, and what waited for room in the ring, every 100 ms.
setInterval(() => { route.flush(); report(); }, 100);
