// nanohaptics play: sound. The page synthesises it: the server's binary sound ticks (per tick
// its wall time and the distance to the nearest object, and the sounds that start on it; see
// protocol/sound.rs's SoundTicks) go to an AudioWorklet (synth.js), which runs the same synthesis as
// `nanohaptics render REC --audio OUT.wav --proximity` at the AudioContext's own sample rate.
// The audio starts on the Start press (a user gesture); `m` mutes it. For the benches, each
// sound's tick → output latency is measured when the worklet renders its first sample. For the
// tests, the page keeps the sounds it was sent and those the worklet played (or lost to a
// drop), and at the session's end the worklet's hash of every sample it played (`P.sound.live`).

import { P, say } from './page.js';

let actx = null, gain = null, node = null, muted = false;
let waiting = []; // sound ticks received while the worklet loads
// The lead (how far the worklet plays behind its own clock), s: the worklet sizes it from the
// ticks' measured arrival jitter (synth.js), past the earliest arrival at least LEAD_S until
// it has measured 4 s and at most LEAD_MAX_S (a stall longer than that underruns and its
// backlog is dropped).
const LEAD_S = 0.008;
const LEAD_MAX_S = 0.03;
// The output's buffer, s: the smallest the device offers (the browser clamps the hint to its
// device's minimum: 128 frames on headless Chromium's fake output, against 10 ms rendered in
// bursts of 3 to 4 quanta at 'interactive').
const LATENCY_HINT_S = 0.001;
const SYNTH_URL = new URL('./synth.js', import.meta.url);

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
      for (const b of waiting) node.port.postMessage(b, b instanceof ArrayBuffer ? [b] : []);
      waiting = [];
    }).catch(() => { node = null; say('sound is not available in this browser'); });
  } catch (err) { actx = null; say('sound is not available in this browser'); }
}

// Sound on or off.
export function toggleMute() {
  muted = !muted;
  if (gain) gain.gain.value = muted ? 0 : 1;
  say(muted ? 'sound off' : 'sound on');
}

// One binary sound-ticks message (an ArrayBuffer): counted, then to the worklet.
export function onSoundTicks(buf) {
  const s = P.sound;
  if (buf.byteLength >= 24) {
    const dv = new DataView(buf);
    const first = Number(dv.getBigUint64(0, true));
    if (s.firstTick < 0) s.firstTick = first;
    else if (first !== s.nextTick) s.gaps++;
    const nt = dv.getUint32(16, true), ns = dv.getUint32(20, true);
    s.nextTick = first + nt; s.ticks += nt; s.sounds += ns;
    // Each sound: its tick (u64) and its index in the session's list (u32).
    for (let j = 0, at = 24 + 16 * nt; j < ns && at + 24 <= buf.byteLength && s.sent.length < 100000; j++, at += 24) {
      const tick = Number(dv.getBigUint64(at, true));
      s.sent.push([tick, dv.getUint32(at + 8, true)]);
      // Tick → the page has it (before the worklet), ms.
      const i = tick - first;
      if (j === 0 && i >= 0 && i < nt && s.pageMs.length < 100000) s.pageMs.push(Date.now() - dv.getFloat64(24 + 16 * i, true));
    }
  }
  s.messages++;
  if (!actx) return;
  if (node) node.port.postMessage(buf, [buf]);
  else if (waiting.length < 2000) waiting.push(buf);
}

// A new world (a lesson's next step) whose ticks start again at 0: the synthesis starts a new
// stream at its first sound ticks.
export function restartAudio() {
  P.sound.restarts++; P.sound.nextTick = 0;
  if (!actx) return;
  if (node) node.port.postMessage({ restart: true });
  else waiting.push({ restart: true });
}

// The session ended after `ticks` ticks: the worklet plays its last samples, then reports.
export function finishAudio(ticks) {
  if (!actx) return;
  if (node) node.port.postMessage({ finish: ticks });
  else waiting.push({ finish: ticks });
}

// The worklet's reports: the end of the stream (what it heard), a sound lost to a drop, or a
// sound's first sample rendered.
function onWorklet(m) {
  const s = P.sound;
  if (m.kind === 'done') {
    s.live = m;
    s.underruns = m.underruns; s.dropped = m.dropped; s.limited = m.limited; s.leadMs = m.leadMs; s.jitterMs = m.jitterMs;
  }
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
  s.underruns = m.underruns; s.dropped = m.dropped; s.limited = m.limited; s.leadMs = m.leadMs; s.jitterMs = m.jitterMs;
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
