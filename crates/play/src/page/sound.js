// nanohaptics play: sound. Plays the server's binary sound blocks (a 16-byte header: the first
// sample's index, u64 little-endian, and its tick's wall time, f64 ms since the Unix epoch;
// then f32 little-endian mono samples at the hello's sample_rate_hz) on a Web Audio clock a
// little ahead of now, and measures tick-to-speaker latency for the benches.

import { P, say } from './page.js';

const HEADER_BYTES = 16;
let actx = null, gain = null, muted = false, base = null;
const LEAD_S = 0.02; // jitter buffer: the blocks' arrival jitter on loopback is ~10 ms

// Opens the audio output at the hello's sample rate (on the Start press: a user gesture).
export function startAudio() {
  try {
    actx = new AudioContext({ sampleRate: P.hello.sample_rate_hz, latencyHint: 'interactive' });
    gain = actx.createGain(); gain.connect(actx.destination);
    actx.resume();
  } catch (err) { actx = null; say('sound is not available in this browser'); }
}

// Sound on or off.
export function toggleMute() {
  muted = !muted;
  if (gain) gain.gain.value = muted ? 0 : 1;
  say(muted ? 'sound off' : 'sound on');
}

// One binary sound block (an ArrayBuffer): hashed for the tests, then scheduled.
export function onPcm(buf) {
  const dv = new DataView(buf);
  const first = Number(dv.getBigUint64(0, true));
  const wallMs = dv.getFloat64(8, true);
  const bytes = new Uint8Array(buf, HEADER_BYTES);
  const n = bytes.length / 4;
  const pc = P.pcm;
  if (pc.first < 0) pc.first = first;
  let h = pc.hash;
  for (let i = 0; i < bytes.length; i++) { h ^= bytes[i]; h = Math.imul(h, 0x01000193) >>> 0; }
  pc.hash = h; pc.samples += n; pc.blocks++;
  if (!actx || n === 0) return;
  const sr = P.hello.sample_rate_hz;
  const data = new Float32Array(buf.slice(HEADER_BYTES));
  const ab = actx.createBuffer(1, n, sr);
  ab.copyToChannel(data, 0);
  if (base === null || base + first / sr < actx.currentTime + 0.005) {
    if (base !== null) pc.underruns++;
    base = actx.currentTime + LEAD_S - first / sr;
  }
  let at = base + first / sr;
  // Blocks that keep arriving early (a late first block, clock drift): come back to the lead.
  const slack = at - actx.currentTime;
  if (slack > LEAD_S + 0.008) {
    if (++pc.early > 20) { base -= slack - LEAD_S; at = base + first / sr; pc.early = 0; pc.rebased++; }
  } else pc.early = 0;
  const src = actx.createBufferSource(); src.buffer = ab; src.connect(gain); src.start(at);
  // Tick to speaker: when this block's first sample leaves the output (the output timestamp
  // maps the context's clock to the page's; it already counts the output device's latency),
  // minus its tick's wall time. Parts: tick → block here, the scheduling lead, and the
  // browser's output pipeline (the rest).
  if (actx.getOutputTimestamp && wallMs > 0) {
    const ts = actx.getOutputTimestamp();
    P.outputLatencyS = actx.outputLatency || 0;
    if (ts.performanceTime > 0 && P.audioLatencyMs.length < 100000) {
      const nowWall = performance.timeOrigin + performance.now();
      const playWall = performance.timeOrigin + ts.performanceTime + (at - ts.contextTime) * 1000;
      const total = playWall - wallMs, arrive = nowWall - wallMs, lead = (at - actx.currentTime) * 1000;
      P.audioLatencyMs.push(total);
      P.audioParts.push([arrive, lead, total - arrive - lead]);
    }
  }
}
