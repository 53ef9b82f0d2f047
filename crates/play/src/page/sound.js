// nanohaptics play: sound. The page synthesises it: the server's binary sound ticks (per tick
// its wall time and the distance to the nearest object, and the sounds that start on it; see
// protocol/sound.rs's SoundTicks) go from the link worker (link.js, route.js) straight to an
// AudioWorklet (synth.js) through a MessagePort, never through this thread; the worklet runs
// the same synthesis as `nanohaptics render REC --audio OUT.wav --proximity` at the
// AudioContext's own sample rate. The audio starts on the Start press (a user gesture); `m`
// mutes it. For the benches, each sound's tick → output latency is measured when the worklet
// renders its first sample. For the tests, the page keeps the sounds it was sent (counted by
// the link) and those the worklet played (or lost to a drop), and at the session's end the
// worklet's hash of every sample it played (`P.sound.live`).

import { P, say } from './page.js';
import { toLink } from './messages.js';

let actx = null, gain = null, node = null, muted = false;
// The lead (how far the worklet plays behind its own clock), s: the worklet sizes it from the
// ticks' measured arrival jitter (synth.js: 95 % of them in time, the rest guessed over), past
// the earliest arrival at least LEAD_S until it has measured 4 s and at most LEAD_MAX_S.
const LEAD_S = 0.005;
const LEAD_MAX_S = 0.03;
// The output's buffer, s: the smallest the device offers (the browser clamps the hint to its
// device's minimum: 128 frames on headless Chromium's fake output, against 10 ms rendered in
// bursts of 3 to 4 quanta at 'interactive').
const LATENCY_HINT_S = 0.001;
const SYNTH_URL = new URL('./synth.js', import.meta.url);
// The sound ring's data, bytes: 1 MiB, about 30 s of the server's sound ticks (a 2-tick
// message is about 56 bytes, 500 a second) should the audio thread stop reading.
const RING_BYTES = 1 << 20;

// Opens the audio output (on the Start press: a user gesture) and loads the synthesis.
export function startAudio() {
  try {
    actx = new AudioContext({ latencyHint: LATENCY_HINT_S });
    gain = actx.createGain(); gain.gain.value = muted ? 0 : 1; gain.connect(actx.destination);
    actx.resume();
    P.sound.sampleRate = actx.sampleRate;
    P.sound.baseLatencyS = actx.baseLatency || 0;
    actx.audioWorklet.addModule(SYNTH_URL).then(() => {
      node = new AudioWorkletNode(actx, 'nh-synth', {
        numberOfInputs: 0, numberOfOutputs: 1, outputChannelCount: [1],
        processorOptions: { rateHz: P.hello ? P.hello.rate_hz : 1000, leadS: LEAD_S, leadMaxS: LEAD_MAX_S },
      });
      node.port.onmessage = (e) => onWorklet(e.data);
      node.connect(gain);
      // The link's way to the worklet: the sound ticks (and what waited) go through it. A
      // ring both read and write (shared memory, on a cross-origin isolated page: the server
      // asks for it), else a port of their own.
      if (globalThis.crossOriginIsolated && typeof SharedArrayBuffer === 'function') {
        const ring = new SharedArrayBuffer(8 + RING_BYTES);
        node.port.postMessage({ ring });
        toLink({ ring });
        P.sound.ring = true;
      } else {
        const ch = new MessageChannel();
        node.port.postMessage({ link: ch.port1 }, [ch.port1]);
        toLink({ port: ch.port2 }, [ch.port2]);
        P.sound.ring = false;
      }
    }).catch(() => { node = null; toLink({ audio: 'none' }); say('sound is not available in this browser'); });
    // The link keeps the ticks from now until the worklet's port comes.
    toLink({ audio: 'on' });
  } catch (err) { actx = null; toLink({ audio: 'none' }); say('sound is not available in this browser'); }
}

// Sound on or off.
export function toggleMute() {
  muted = !muted;
  if (gain) gain.gain.value = muted ? 0 : 1;
  say(muted ? 'sound off' : 'sound on');
}

// The link's reports: its counts of the sound ticks (the same fields as before the link had a
// worker; `linkMs`: tick → the link worker has it, per message with a sound), and the wall
// time of a tick with a sound as the link passes it on (`pageMs`: tick → this thread has it).
export function onLinkReport(d) {
  const s = P.sound;
  if (d.counts) {
    const c = d.counts;
    for (const k of ['messages', 'ticks', 'sounds', 'firstTick', 'nextTick', 'gaps', 'restarts', 'overflow']) s[k] = c[k];
    for (const x of c.sent) s.sent.push(x);
    for (const x of c.linkMs) s.linkMs.push(x);
  } else if (Number.isFinite(d.stamp) && s.pageMs.length < 100000) s.pageMs.push(Date.now() - d.stamp);
}

// The worklet's counts, as its latest report (an onset or the end) gives them.
function counts(s, m) {
  s.underruns = m.underruns; s.guesses = m.guesses; s.concealed = m.concealedSamples; s.dropped = m.dropped;
  s.skipped = m.skipped; s.waited = m.waited;
  s.limited = m.limited; s.leadMs = m.leadMs; s.jitterMs = m.jitterMs; s.cadence = m.cadence; s.spread = m.spread;
}

// The worklet's reports: the end of the stream (what it heard), a stream a restart ended (a
// lesson's world before the next: what it heard), a sound lost to a drop, or a sound's first
// sample rendered.
function onWorklet(m) {
  const s = P.sound;
  if (m.kind === 'done') {
    s.live = m;
    counts(s, m);
  }
  else if (m.kind === 'stream') s.streams.push(m);
  else if (m.kind === 'lost') s.lost.push([m.tick, m.index]);
  else { if (s.played.length < 100000) s.played.push([m.tick, m.index]); onRendered(m); }
}

// The worklet rendered a sound's first sample: tick → output, two ways. `latencyMs`: the
// render time (the audio thread's Date.now() for the render quantum, plus the frame's place
// in it) plus the context's baseLatency and outputLatency, minus the tick's wall time.
// `latencyTsMs`: the frame's context time mapped to the page's clock through
// getOutputTimestamp() (the output's own estimate of when it plays), minus the same.
function onRendered(m) {
  const s = P.sound;
  counts(s, m);
  if (s.latencyMs.length >= 100000) return;
  const outS = actx.outputLatency || 0, baseS = actx.baseLatency || 0;
  s.outputLatencyS = outS; s.baseLatencyS = baseS;
  const rendered = m.renderMs + (m.frame / m.sampleRate) * 1000;
  s.latencyMs.push(rendered + (outS + baseS) * 1000 - m.wallMs);
  // Parts: tick → the worklet has it, queued in the worklet, the output's latency.
  s.parts.push([m.gotMs - m.wallMs, rendered - m.gotMs, (outS + baseS) * 1000]);
  const ts = actx.getOutputTimestamp ? actx.getOutputTimestamp() : null;
  if (ts && ts.performanceTime > 0) {
    const out = performance.timeOrigin + ts.performanceTime + (m.contextTime - ts.contextTime) * 1000;
    s.latencyTsMs.push(out - m.wallMs);
  }
}
