// nanohaptics play: what every module of the page shares. The element lookup, the figures the
// tests and benches read (window.__play), and the spoken log (the Events list, an ARIA live
// region, and the assertive announcer).

export const $ = (id) => document.getElementById(id);

// Figures for tests and benches; the modules fill them in as messages arrive.
export const P = (window.__play = {
  hello: null, role: null, frames: 0, draws: 0, drawT0: 0, lastFrame: null,
  events: [], sounds: [], switched: [], errors: [], ended: null,
  sound: {
    messages: 0, ticks: 0, sounds: 0, firstTick: -1, nextTick: 0, gaps: 0, overflow: 0, ring: null, sampleRate: null,
    underruns: 0, guesses: 0, concealed: 0, dropped: 0, skipped: 0, waited: 0, limited: 0, leadMs: null, jitterMs: null, cadence: null, spread: null, outputLatencyS: null, baseLatencyS: null,
    latencyMs: [], latencyTsMs: [], parts: [], pageMs: [], linkMs: [],
    sent: [], played: [], lost: [], live: null, streams: [], restarts: 0,
  },
  inputsSent: 0,
  said: [], menu: {},
  lesson: null, lessons: [], answersSent: 0, stepEnds: [],
});

const logEl = $('log');

// Writes `text` to the Events list (screen readers read it politely).
export function log(text) {
  if (P.said.length < 10000) P.said.push(text);
  const p = document.createElement('p'); p.textContent = text; logEl.appendChild(p);
  while (logEl.childNodes.length > 60) logEl.removeChild(logEl.firstChild);
  logEl.scrollTop = logEl.scrollHeight;
}

// Announces `text` at once (assertive) and writes it to the Events list.
export function say(text) { $('announce').textContent = text; log(text); }
