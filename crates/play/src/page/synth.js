// nanohaptics play: the sound synthesis, an AudioWorklet processor (loaded by sound.js with
// audioWorklet.addModule; it runs on the audio thread). A port of crates/render/src/audio.rs's
// StreamSynth, formula for formula in the same f64 arithmetic, at the AudioContext's sample
// rate: impacts, snap and pull-off voices (0.5 ms attack, exponential decay, each normalised to
// its peak amplitude), the proximity tone (220 Hz → 880 Hz below the on-distance, pitch and
// amplitude interpolated between tick centres, phase continuous), and samples beyond the
// ±0.98 ceiling limited to it. Its input is the server's binary sound ticks (protocol/sound.rs's
// SoundTicks): per tick its wall time and nearest distance, and the sounds starting on it,
// with the restarts and finishes, which come from the page's link worker (link.js, route.js)
// through a ring in shared memory it reads before each render quantum (the page posts the
// SharedArrayBuffer to the node's port as `{ ring: sab }`), or, without shared memory, on a
// MessagePort of their own (`{ link: port }`).
//
// The samples go through a FIFO to the output, which plays a lead behind the processor's
// clock sized from the ticks' measured arrival jitter. The processor counts the samples it
// has output (`clock`, silence included); for each message that brings new samples, its
// lateness is the clock at its arrival (the next render quantum's) minus the session index of
// its first new sample (the two origins differ by a constant: only differences of lateness
// mean something). The output plays sample `clock − lead` at each clock, the lead being the
// 95th percentile of the lateness of the last 4 s (eight 0.5 s buckets, taken each time the
// window moves on) plus a 1 ms margin: 95 % of the messages arrive before the quantum that
// plays their first sample. The lead is at most `leadMaxS` past the window's earliest arrival,
// and while less than 4 s has been measured at least `leadS` past it. The measuring starts
// afresh when a stream first plays (what came before was its start-up backlog, not the link's
// jitter) and at a restart.
//
// A message later than the lead is *guessed over*: when the FIFO runs short, the synthesis
// goes on as if the ticks to come held the last one (its tone, no sound starting; at most
// GUESS_MAX_S), from a copy of itself as the ticks left it. That is what the world sounds like
// unless a sound starts or the tone moves, so most guesses are the track's samples to the bit.
// When the ticks come, the synthesis goes back to the copy and runs them: the guessed samples
// still queued are replaced, and those already played are checked against what the ticks
// make (the same bits: heard, as any other; else *concealed*: played, listed, not hashed). A
// sound whose first sample was played over as a guess starts at once, on the first sample
// not yet played, and the samples it spans are concealed: a late sound is late by its
// message's lateness, not lost and not held for a lead.
//
// Playback starts, and restarts after an underrun, once the clock is a lead past the next
// sample (and a quantum of it is queued); a stream whose first sample is already more than
// 5 ms past that (its start-up backlog) drops the samples due and starts on the lead. While
// the output plays silence it follows the lead to the sample: it waits (silence, not hashed)
// where the lead grew past it, and skips silent samples queued where the lead fell behind it
// (listed and counted apart from drops; never past a sample that sounds). While it sounds, a
// lead that grew is guessed over until the next silence; an underrun (silence, then the wait)
// happens only where a guess cannot help, a stall outlasting GUESS_MAX_S. Every 0.1 s of
// quanta, when the output plays more than 5 ms behind the lead (a backlog after a stall, or
// jitter that has passed), the excess is dropped (counted and listed), sound or not, never
// below one quantum queued at the window's lowest. For
// each sound's first sample the processor reports when it was rendered (Date.now() at the
// render quantum, the frame within it, the context time) so the page can measure tick →
// output, or that it was dropped (`lost`). It hashes
// every sample it plays from the FIFO (FNV-1a over the Float32 bytes, in the order played;
// the silence of a wait or an underrun is not the session's and is not hashed) and keeps where
// it dropped samples, so the test can compare what was heard with `render --audio`. A
// `{ finish: ticks }` message (the session ended after `ticks` ticks) ends the stream as
// StreamSynth::finish does: the last samples are queued and played, the FIFO running empty then
// is the end rather than an underrun, and the processor reports `done` with the hash. With
// `offline` options (a test's OfflineAudioContext) it takes all its ticks at construction and
// plays from sample 0. A `{ restart: true }` message (a lesson's next world) reports what the
// stream so far heard (`stream`, whether or not it was played to its end) and starts a new one,
// its hash, drops and `first` afresh (`restarts` 1); underruns and drops stay counted.

const A_MAX = 0.8, CEILING = 0.98, ATTACK_S = 5e-4, TONE_AMPLITUDE = 0.12;
const TAU = 2 * Math.PI; // std::f64::consts::TAU
const SILENT = [0, 0];
const HEADER = 24, TICK = 16, SOUND = 24;
// The lead's window (LATE_BUCKETS buckets of LATE_BUCKET_S of the processor's clock), the margin
// on top of the largest lateness, and the excess over the lead that is dropped, s.
const LATE_BUCKETS = 8, LATE_BUCKET_S = 0.5, MARGIN_S = 0.001, TRIM_S = 0.005;
// The share of the window's messages the lead covers (the rest are guessed over, see above),
// and the longest guess, s (a longer stall underruns).
const LEAD_QUANTILE = 0.95, GUESS_MAX_S = 0.05;

// What a stream heard, afresh (see the processor's `heard`): `restarts` 1 after a restart.
function heardAfresh(restarts) {
  return { hash: 0x811c9dc5, played: 0, first: -1, checkpoints: [], drops: [], skips: [], concealed: [], restarts };
}

// 64-bit unsigned arithmetic on [hi, lo] 32-bit halves (the noise is xorshift64*).
function mul64(ah, al, bh, bl) {
  const a48 = ah >>> 16, a32 = ah & 0xffff, a16 = al >>> 16, a00 = al & 0xffff;
  const b48 = bh >>> 16, b32 = bh & 0xffff, b16 = bl >>> 16, b00 = bl & 0xffff;
  let c48 = 0, c32 = 0, c16 = 0, c00 = 0;
  c00 += a00 * b00; c16 += c00 >>> 16; c00 &= 0xffff;
  c16 += a16 * b00; c32 += c16 >>> 16; c16 &= 0xffff;
  c16 += a00 * b16; c32 += c16 >>> 16; c16 &= 0xffff;
  c32 += a32 * b00; c48 += c32 >>> 16; c32 &= 0xffff;
  c32 += a16 * b16; c48 += c32 >>> 16; c32 &= 0xffff;
  c32 += a00 * b32; c48 += c32 >>> 16; c32 &= 0xffff;
  c48 += a48 * b00 + a32 * b16 + a16 * b32 + a00 * b48; c48 &= 0xffff;
  return [((c48 << 16) | c32) >>> 0, ((c16 << 16) | c00) >>> 0];
}

// audio.rs's Noise: xorshift64* seeded with seed · 0x9E3779B97F4A7C15 | 1, values in [-1, 1).
class Noise {
  constructor(seed) {
    const [h, l] = mul64(0, seed >>> 0, 0x9e3779b9, 0x7f4a7c15);
    this.h = h; this.l = (l | 1) >>> 0;
  }
  next() {
    let h = this.h, l = this.l, nh, nl;
    // x ^= x >> 12
    nl = (l >>> 12) | (h << 20); nh = h >>> 12; h = (h ^ nh) >>> 0; l = (l ^ nl) >>> 0;
    // x ^= x << 25
    nh = (h << 25) | (l >>> 7); nl = l << 25; h = (h ^ nh) >>> 0; l = (l ^ nl) >>> 0;
    // x ^= x >> 27
    nl = (l >>> 27) | (h << 5); nh = h >>> 27; h = (h ^ nh) >>> 0; l = (l ^ nl) >>> 0;
    this.h = h; this.l = l;
    const [mh, ml] = mul64(h, l, 0x2545f491, 0x4f6cdd1d);
    // v = x · 0x2545F4914F6CDD1D >> 11 (53 bits: exact as a double)
    const v = (mh >>> 11) * 4294967296 + (((ml >>> 11) | (mh << 21)) >>> 0);
    return v / 9007199254740992 * 2 - 1;
  }
}

// audio.rs's voice: (length s, waveform of τ s after the onset, before normalising).
function voice(kind, seed) {
  const attack = (tau) => Math.min(tau / ATTACK_S, 1);
  const noise = new Noise(seed);
  if (kind <= 2) {
    const [f1, f2, decay, mix] = [[140.0, 310.0, 0.060, 0.35], [520.0, 1250.0, 0.040, 0.25], [900.0, 2100.0, 0.015, 0.15]][kind];
    return [6.0 * decay, (tau) => {
      const env = attack(tau) * Math.exp(-tau / decay);
      const tone = 0.65 * Math.sin(TAU * f1 * tau) + 0.35 * Math.sin(TAU * f2 * tau);
      return env * ((1.0 - mix) * tone + mix * noise.next());
    }];
  }
  if (kind === 3) {
    return [0.012, (tau) => attack(tau) * Math.exp(-tau / 0.002) * Math.sin(TAU * 2400.0 * tau)];
  }
  return [0.05, (tau) => {
    const env = attack(tau) * Math.exp(-tau / 0.008);
    const phase = TAU * (300.0 * tau + 600.0 * 0.01 * (1.0 - Math.exp(-tau / 0.01)));
    return env * Math.sin(phase);
  }];
}

// audio.rs's event_samples: the first sample index and the samples one sound adds (null: none).
function eventSamples(tS, kind, amplitude, index, sr) {
  if (!(Number.isFinite(tS) && tS >= 0)) return null;
  const a = Math.min(Math.max(amplitude, 0), A_MAX);
  if (a === 0) return null;
  const start = Math.round(tS * sr);
  const [lenS, wave] = voice(kind, index + 1);
  const len = Math.ceil(lenS * sr);
  const s = new Float64Array(len);
  let norm = 0;
  for (let k = 0; k < len; k++) { const v = wave(k / sr); norm = Math.max(norm, Math.abs(v)); s[k] = v; }
  const g = norm > 0 ? a / norm : 0;
  for (let k = 0; k < len; k++) s[k] = g * s[k];
  return [start, s];
}

// audio.rs's tone_at: (pitch Hz, amplitude) at distance d, (0, 0) when silent or unknown.
function toneAt(d, on) {
  if (d === undefined || !(Number.isFinite(d) && d < on && on > 0)) return [0, 0];
  const x = Math.min(Math.max(1.0 - Math.max(d, 0) / on, 0), 1);
  return [220.0 * Math.pow(4, x), TONE_AMPLITUDE];
}

// audio.rs's StreamSynth, from tick `firstTick` on; samples go to `out(v)` as they complete.
class StreamSynth {
  constructor(sr, dt, on, firstTick, out) {
    this.sr = sr; this.dt = dt; this.on = on; this.out = out;
    this.pending = []; this.ph = 0; // sums of the sounds from nextSample on
    this.distances = []; this.dh = 0;
    this.baseTick = firstTick; this.ticks = firstTick;
    // The first sample of tick `firstTick` (0 from the session's start).
    let k = Math.floor(firstTick * dt * sr);
    while (k > 0 && Math.floor((k - 1) / sr / dt) >= firstTick) k--;
    while (Math.floor(k / sr / dt) < firstTick) k++;
    this.nextSample = k;
    this.phase = 0; this.lastF = 220.0;
    this.limited = 0;
  }
  // A sound at `tS`; `at`: the sample it starts on instead (a late sound played at once), or
  // undefined. Returns [the sample it starts on, its length], or null when it is silent.
  push(tS, kind, amplitude, index, at) {
    const e = eventSamples(tS, kind, amplitude, index, this.sr);
    if (e === null) return null;
    const s = e[1], start = at === undefined ? e[0] : at;
    for (let k = 0; k < s.length; k++) {
      const rel = start + k - this.nextSample;
      if (rel < 0) continue;
      const at = this.ph + rel;
      while (this.pending.length <= at) this.pending.push(0);
      this.pending[at] += s[k];
    }
    return [start, s.length];
  }
  // The tone's (pitch, amplitude) at each tick are kept rather than its distance: the same
  // values, computed once per tick.
  tick(d) { this.distances.push(this.on === null ? null : toneAt(d, this.on)); this.ticks++; this.emit(-1); }
  // A tick whose data has not come: the last tick's tone held, no sound starting on it.
  hold() {
    const n = this.distances.length;
    this.distances.push(n > this.dh ? this.distances[n - 1] : (this.on === null ? null : SILENT));
    this.ticks++; this.emit(-1);
  }
  finish(durationS) { this.emit(Math.round(durationS * this.sr)); }
  // A copy of the synthesis as it stands (the sounds still to sum, the tones to come, the
  // phase), writing to the same output.
  clone() {
    const c = Object.create(StreamSynth.prototype);
    Object.assign(c, this);
    c.pending = this.pending.slice(this.ph); c.ph = 0;
    c.distances = this.distances.slice(this.dh); c.dh = 0;
    return c;
  }
  at(j) {
    const r = j - this.baseTick;
    const v = r >= 0 ? this.distances[this.dh + r] : undefined;
    return v === undefined ? SILENT : v;
  }
  emit(end) {
    const sr = this.sr, dt = this.dt;
    for (;;) {
      const k = this.nextSample;
      if (end >= 0 && k >= end) break;
      const t = k / sr / dt;
      const i = Math.floor(t);
      if (end < 0 && i + 1 >= this.ticks) break;
      let v = 0;
      if (this.ph < this.pending.length) v = this.pending[this.ph++];
      if (this.on !== null) {
        const w = t - Math.floor(t);
        const [f0, a0] = this.at(i), [f1, a1] = this.at(i + 1);
        const amp = a0 * (1.0 - w) + a1 * w;
        let f;
        if (a0 > 0 && a1 > 0) f = f0 * (1.0 - w) + f1 * w;
        else if (a0 > 0) f = f0;
        else if (a1 > 0) f = f1;
        else f = this.lastF;
        this.lastF = f;
        this.phase = (this.phase + TAU * f / sr) % TAU;
        v += amp * Math.sin(this.phase);
      }
      if (Math.abs(v) > CEILING) { this.limited++; v = v < 0 ? -CEILING : CEILING; }
      this.out(v, k);
      this.nextSample++;
      while (this.baseTick < i && this.dh < this.distances.length) { this.dh++; this.baseTick++; }
    }
    if (this.ph > 4096 && this.ph * 2 > this.pending.length) { this.pending.splice(0, this.ph); this.ph = 0; }
    if (this.dh > 4096) { this.distances.splice(0, this.dh); this.dh = 0; }
  }
}

// The samples waiting for the output (Float32: the cast of StreamSynth's `v as f32`), with the
// session index of the first one.
class Fifo {
  constructor() { this.buf = new Float32Array(1 << 14); this.head = 0; this.tail = 0; this.first = 0; }
  get length() { return this.tail - this.head; }
  push(v) {
    if (this.tail === this.buf.length) {
      const n = this.length;
      if (n * 2 > this.buf.length) {
        const b = new Float32Array(this.buf.length * 2);
        b.set(this.buf.subarray(this.head, this.tail)); this.buf = b;
      } else this.buf.copyWithin(0, this.head, this.tail);
      this.head = 0; this.tail = n;
    }
    this.buf[this.tail++] = v;
  }
  // Moves up to out.length samples to `out` from `at`; returns how many.
  take(out, at) {
    const n = Math.min(out.length - at, this.length);
    out.set(this.buf.subarray(this.head, this.head + n), at);
    this.head += n; this.first += n;
    return n;
  }
  drop(n) { n = Math.min(n, this.length); this.head += n; this.first += n; }
  // Keeps the first `n` samples queued, forgets the rest.
  truncate(n) { this.tail = this.head + Math.max(0, Math.min(n, this.length)); }
  clear(first) { this.head = 0; this.tail = 0; this.first = first; }
}

// The sound ring's reading end (route.js's SoundRing writes it; the layout is there): the
// records the link worker wrote, in order, each once.
class RingReader {
  constructor(sab) {
    this.at = new Int32Array(sab, 0, 2);
    this.data = new Uint8Array(sab, 8);
    this.cap = this.data.length;
  }

  // The next record, [kind, payload (an ArrayBuffer of its own)], or null when there is none.
  next() {
    const w = Atomics.load(this.at, 0), r = Atomics.load(this.at, 1);
    if (w === r) return null;
    const dv = new DataView(this.get(r, 8).buffer);
    const len = dv.getUint32(0, true), kind = dv.getUint32(4, true);
    const body = this.get((r + 8) % this.cap, len);
    Atomics.store(this.at, 1, (r + 8 + len) % this.cap);
    return [kind, body.buffer];
  }

  get(at, n) {
    const out = new Uint8Array(n), first = Math.min(n, this.cap - at);
    out.set(this.data.subarray(at, at + first));
    if (first < n) out.set(this.data.subarray(0, n - first), first);
    return out;
  }
}

// Counts of values in bins of `width` from 0 (the last bin: everything from its start on),
// and the nearest-rank percentiles of what was counted, as the bin's start.
class Hist {
  constructor(bins, width) { this.bins = new Uint32Array(bins); this.width = width; this.n = 0; }
  add(x) { this.bins[Math.min(this.bins.length - 1, Math.max(0, Math.floor(x / this.width)))]++; this.n++; }
  at(q) {
    let c = 0;
    for (let b = 0; b < this.bins.length; b++) { c += this.bins[b]; if (c >= q * this.n) return b * this.width; }
    return (this.bins.length - 1) * this.width;
  }
}

// The audio thread's render cadence, in the wall clock: quanta rendered back to back (within
// 1 ms of the one before; Date.now() counts whole ms) are one callback of the output device. A
// device that renders k quanta at a time makes every arrival look up to k quanta late against
// the processor's clock however punctual it was, so the lead must cover a callback: this
// measures how many quanta a callback renders and how often one comes (a probe: it changes
// nothing that is played).
class Cadence {
  constructor() {
    this.last = -Infinity; this.start = -Infinity; this.size = 0;
    this.sizes = new Uint32Array(33); // callbacks by their quanta (32: 32 or more)
    this.gaps = new Hist(201, 1); // callbacks by the ms from the one before (200: 200 or more)
  }

  quantum(now) {
    if (now - this.last <= 1) this.size++;
    else {
      if (this.size > 0) {
        this.sizes[Math.min(this.size, 32)]++;
        if (Number.isFinite(this.start)) this.gaps.add(now - this.start);
      }
      this.start = now; this.size = 1;
    }
    this.last = now;
  }

  // The quanta of a callback (the most frequent, the largest) and the ms between callbacks
  // (p50, p99); null before two callbacks.
  report() {
    let mode = 0, max = 0;
    for (let k = 1; k < this.sizes.length; k++) {
      if (this.sizes[k] > this.sizes[mode]) mode = k;
      if (this.sizes[k]) max = k;
    }
    const g = this.gaps;
    if (!g.n) return null;
    return { quanta: [mode, max], ms: [g.at(0.5), g.at(0.99)], callbacks: g.n };
  }
}

class Synth extends AudioWorkletProcessor {
  constructor(options) {
    super();
    const o = options.processorOptions || {};
    this.dt = 1 / (o.rateHz || 1000);
    this.fifo = new Fifo();
    this.synth = null;
    this.onsets = []; // [sample index, tick, tick wall ms, arrival ms]
    // The lead, samples (see above): past the earliest arrival, at least `lead0` before the
    // jitter is measured, at most `leadMax`.
    this.lead0 = Math.round((o.leadS || 0) * sampleRate);
    this.leadMax = Math.round((o.leadMaxS || 0.03) * sampleRate);
    this.lead = this.lead0;
    this.margin = Math.round(MARGIN_S * sampleRate);
    this.trim = Math.round(TRIM_S * sampleRate);
    // The processor's clock (samples output, silence included), the lateness of the arrivals
    // (the largest and the smallest per bucket of the clock), and the clock when the
    // measuring began.
    this.clock = 0;
    this.bucketLen = Math.round(LATE_BUCKET_S * sampleRate);
    this.late = new Float64Array(LATE_BUCKETS).fill(-Infinity);
    this.early = new Float64Array(LATE_BUCKETS).fill(Infinity);
    this.lates = Array.from({ length: LATE_BUCKETS }, () => []);
    this.quantile = -Infinity; // LEAD_QUANTILE of the window's lateness, at its last move
    this.bucket = -1; this.since = -1;
    // The guess over a late message (see above): null, or the synthesis as the ticks left it
    // (`snap`), the session index of the first sample guessed (`from`) and the values guessed
    // from it (Float32; those before the FIFO's first were played). `deviate`: the session
    // samples [from, to) that are not the track's (a late sound played at once).
    this.guess = null; this.guessing = false; this.deviate = [0, 0];
    this.guesses = 0; this.concealedSamples = 0;
    this.one = new Float32Array(1);
    this.primed = false;
    this.underruns = 0; this.dropped = 0;
    // Silent samples skipped and waited to follow the lead (see follow), and the last sample
    // the output played from the FIFO (0 after silence).
    this.skipped = 0; this.waited = 0; this.lastOut = 0;
    this.minLevel = Infinity; this.quanta = 0;
    this.offline = !!o.offline;
    this.cadence = new Cadence();
    // Each message's lateness past its window's earliest, in 0.5 ms bins to 100 ms (a probe:
    // what sizes the lead, the bulk or its rare late messages).
    this.spread = new Hist(201, 0.5);
    // What was heard: the FNV-1a hash of the samples played, their count, the first one's
    // session index, a checkpoint of the hash every second played, the [index, count] of each
    // drop, the restarts after a long gap; `ending`: the stream was finished.
    this.heard = heardAfresh(0);
    this.ending = false; this.done = false;
    if (o.offline) {
      for (const b of o.offline.blocks) this.take(b, 0);
      if (this.synth) this.synth.finish(o.offline.ticks * this.dt);
      this.primed = true;
    }
    // The node's port (the page), and the link worker's (`{ link: MessagePort }`, sent by the
    // page through the node's): sound ticks, restarts and finishes, in the order they came.
    // Or the link worker's ring (`{ ring: SharedArrayBuffer }`, on a cross-origin isolated
    // page): the same, read at the start of each render quantum (`drain`).
    this.ring = null;
    const onMessage = (e) => {
      if (e.data instanceof ArrayBuffer) this.take(e.data, Date.now());
      else if (e.data && Number.isFinite(e.data.finish)) this.finish(e.data.finish);
      else if (e.data && e.data.restart) this.restart();
      else if (e.data && e.data.link) e.data.link.onmessage = onMessage;
      else if (e.data && e.data.ring) this.ring = new RingReader(e.data.ring);
    };
    this.port.onmessage = onMessage;
  }

  // A new stream (a lesson's next world, its ticks from 0): what the last one heard is
  // reported (`stream`; `complete`: it was played to its end), then heard afresh.
  restart() {
    this.dropGuess();
    this.port.postMessage({ ...this.report('stream'), complete: this.done });
    // The last stream's samples not yet played are not the new one's.
    this.synth = null; this.ending = false; this.done = false;
    this.fifo.clear(0); this.primed = false; this.onsets = []; this.deviate = [0, 0]; this.lastOut = 0;
    this.heard = heardAfresh(1);
  }

  // The samples the processor makes, in order (`k`: the session index): to the FIFO; while
  // guessing, also kept; once the ticks came, those already played as a guess are checked
  // against it instead (the same bits, not a late sound's: heard; else concealed).
  sample(v, k) {
    const g = this.guess, fifo = this.fifo;
    const f = Math.fround(v);
    if (g !== null && k < fifo.first) {
      if (this.guessing) return; // played already, as the earlier guess
      const dev = k >= this.deviate[0] && k < this.deviate[1];
      const played = g.values[k - g.from];
      if (!dev && played === f) { this.one[0] = played; this.hash(this.one, 0, 1); }
      else this.conceal(k, 1);
      return;
    }
    if (this.guessing) g.values[k - g.from] = f;
    fifo.push(v);
  }

  // The FIFO runs short of `need` samples: a late message. Guess the ticks to come as the last
  // one held (its tone, no sound starting) for at most GUESS_MAX_S: what an idle world sounds
  // like, the samples the ticks will make unless a sound starts or the tone moves. (Also when
  // the lead has grown past where the output plays: the output moves to it in the next
  // silence, see follow, rather than with an underrun's gap while a sound plays.)
  extend(need) {
    const s = this.synth, fifo = this.fifo;
    if (s === null) return;
    if (this.guess === null) {
      this.guess = { snap: s.clone(), from: s.nextSample, values: [] };
      this.guesses++;
    }
    const cap = this.guess.snap.ticks + Math.ceil(GUESS_MAX_S / this.dt);
    this.guessing = true;
    while (fifo.length < need && s.ticks < cap) s.hold();
    this.guessing = false;
  }

  // Ticks came while guessing: back to the synthesis as the ticks left it, the guessed samples
  // still queued forgotten (those played are checked as the ticks make them again).
  unguess() {
    const g = this.guess;
    this.synth = g.snap; g.snap = null;
    this.fifo.truncate(g.from - this.fifo.first);
  }

  // After the ticks: what was played as a guess past them waits for the next ones.
  settle() {
    const g = this.guess, s = this.synth;
    if (g === null || g.snap !== null) return;
    if (s === null || s.nextSample >= this.fifo.first) { this.guess = null; return; }
    g.values = g.values.slice(s.nextSample - g.from); g.from = s.nextSample; g.snap = s.clone();
  }

  // The stream ends or restarts with a guess played: its samples not checked are concealed.
  dropGuess() {
    const g = this.guess;
    if (g === null) return;
    const from = this.synth !== null && g.snap === null ? this.synth.nextSample : g.from;
    if (from < this.fifo.first) this.conceal(from, this.fifo.first - from);
    this.guess = null;
  }

  // Samples [k, k + n) played that are not the track's: listed, not hashed.
  conceal(k, n) {
    const c = this.heard.concealed, last = c[c.length - 1];
    if (last && last[0] + last[1] === k) last[1] += n;
    else if (c.length < 10000) c.push([k, n]);
    this.concealedSamples += n;
  }

  // The session ended after `ticks` ticks: the stream's last samples, then the end.
  finish(ticks) {
    if (this.ending) return;
    if (this.guess !== null) this.unguess();
    const s = this.synth;
    if (s !== null) {
      while (s.ticks < ticks) s.tick(NaN);
      s.finish(ticks * this.dt);
    }
    // A guess played past the stream's end is not the track's.
    this.dropGuess();
    this.ending = true; this.primed = true;
  }

  // Hashes the `n` samples just played from `out` at `at` (session indices from `from`).
  // Guessed samples wait to be checked; those of a late sound played at once are concealed.
  hear(out, at, n, from) {
    if (n > 0 && this.heard.first < 0) this.heard.first = from;
    for (let i = 0; i < n;) {
      const k = from + i, g = this.guess, [lo, hi] = this.deviate;
      if (g !== null && k >= g.from) return;
      if (k >= lo && k < hi) {
        // (Up to the guess: what it played is checked when the ticks come.)
        const m = Math.min(n - i, hi - k, g === null ? Infinity : g.from - k);
        this.conceal(k, m); i += m; continue;
      }
      let m = n - i;
      if (lo > k) m = Math.min(m, lo - k);
      if (g !== null) m = Math.min(m, g.from - k);
      this.hash(out, at + i, m); i += m;
    }
  }

  // Adds `n` samples of `out` from `at` to the hash of what was heard.
  hash(out, at, n) {
    const h = this.heard;
    const bytes = new Uint8Array(out.buffer, out.byteOffset + at * 4, n * 4);
    let x = h.hash;
    for (let i = 0; i < bytes.length; i++) x = Math.imul(x ^ bytes[i], 0x01000193) >>> 0;
    const second = Math.round(sampleRate);
    if (Math.floor((h.played + n) / second) > Math.floor(h.played / second)) h.checkpoints.push([h.played + n, x]);
    h.hash = x; h.played += n;
  }

  // One binary sound-ticks message.
  take(buf, gotMs) {
    const dv = new DataView(buf);
    if (buf.byteLength < HEADER) return;
    const first = Number(dv.getBigUint64(0, true));
    const onRaw = dv.getFloat64(8, true);
    const on = Number.isNaN(onRaw) ? null : onRaw;
    const nt = dv.getUint32(16, true), ns = dv.getUint32(20, true);
    if (buf.byteLength !== HEADER + TICK * nt + SOUND * ns) return;
    let s = this.synth;
    // A gap (messages the server dropped for this page): silent ticks; a long one, a restart.
    if (this.ending) return;
    if (this.guess !== null) { this.unguess(); s = this.synth; }
    if (s !== null && first > s.ticks && first - s.ticks > 5000) { s = null; this.heard.restarts++; }
    if (s === null) {
      this.dropGuess(); this.deviate = [0, 0];
      s = this.synth = new StreamSynth(sampleRate, this.dt, on, first, (v, k) => this.sample(v, k));
      this.fifo.clear(s.nextSample); this.primed = this.offline; this.onsets = [];
      this.forget();
    }
    while (s.ticks < first) s.tick(NaN);
    const from = s.nextSample;
    let j = 0;
    const soundAt = HEADER + TICK * nt;
    for (let i = 0; i < nt; i++) {
      const tick = first + i;
      const wallMs = dv.getFloat64(HEADER + TICK * i, true);
      for (; j < ns; j++) {
        const at = soundAt + SOUND * j;
        const st = Number(dv.getBigUint64(at, true));
        if (st > tick) break;
        if (st < tick || tick < s.ticks) continue;
        const tS = st * this.dt, index = dv.getUint32(at + 8, true);
        // A sound whose first samples were played as a guess (its message was late) starts at
        // once, on the first sample not yet played; the samples it spans are not the track's.
        let k = Math.round(tS * sampleRate);
        const late = k < this.fifo.first;
        const r = s.push(tS, dv.getUint32(at + 12, true), dv.getFloat64(at + 16, true), index, late ? this.fifo.first : undefined);
        if (late) {
          const [lo, hi] = this.deviate, to = r === null ? k : r[0] + r[1];
          this.deviate = hi > lo ? [Math.min(lo, k), Math.max(hi, to)] : [k, to];
          k = this.fifo.first;
        }
        if (!this.offline && k >= s.nextSample && this.onsets.length < 1000) this.onsets.push([k, st, wallMs, gotMs, index]);
      }
      if (tick < s.ticks) continue; // already had
      s.tick(dv.getFloat64(HEADER + TICK * i + 8, true));
    }
    this.settle();
    if (!this.offline && s.nextSample > from) this.arrived(this.clock - from);
  }

  // A message brought new samples `late` samples after the clock passed its first one (the
  // clock then is the next quantum's): the lead is the window's largest lateness plus the
  // margin. A quantum at clock c plays from c − lead, and clocks are multiples of the quantum,
  // so a message no later than the lead arrives before the quantum that plays its first sample.
  arrived(late) {
    if (this.since < 0) { this.since = this.clock; this.bucket = Math.floor(this.clock / this.bucketLen); }
    this.rotate();
    const k = this.bucket % LATE_BUCKETS;
    if (late > this.late[k]) this.late[k] = late;
    if (late < this.early[k]) this.early[k] = late;
    this.lates[k].push(late);
    this.spread.add((late - this.window()[0]) / sampleRate * 1000);
    this.sizeLead();
  }

  // The lateness measured so far is forgotten (the window empties; the lead stands until the
  // next arrival sizes it). At a new stream (a restart, or a gap that restarts the synthesis)
  // its ticks count from another origin; at a stream's first sample played, what came before
  // was its start-up backlog (the ticks the link kept while the worklet loaded, which come at
  // once, the first as late as the load took), not the link's jitter.
  forget() {
    this.late.fill(-Infinity); this.early.fill(Infinity);
    for (const l of this.lates) l.length = 0;
    this.quantile = -Infinity; this.bucket = -1; this.since = -1;
  }

  // The window moves on with the clock: the buckets it left are emptied.
  rotate() {
    const b = Math.floor(this.clock / this.bucketLen);
    if (this.since < 0 || b <= this.bucket) return;
    for (let i = Math.max(this.bucket + 1, b - LATE_BUCKETS + 1); i <= b; i++) {
      const k = i % LATE_BUCKETS;
      this.late[k] = -Infinity; this.early[k] = Infinity; this.lates[k].length = 0;
    }
    this.bucket = b;
    // The window's LEAD_QUANTILE lateness (nearest rank), once each time the window moves.
    const all = [];
    for (const l of this.lates) for (const x of l) all.push(x);
    all.sort((x, y) => x - y);
    this.quantile = all.length ? all[Math.max(0, Math.ceil(LEAD_QUANTILE * all.length) - 1)] : -Infinity;
  }

  // The lead from the window's lateness: its LEAD_QUANTILE plus the margin, between lead0
  // (while the window is not full) and leadMax past its smallest.
  sizeLead() {
    this.rotate();
    const [early, late] = this.window();
    if (!Number.isFinite(late)) return;
    let lead = Math.max(this.quantile, early) + this.margin;
    if (this.clock - this.since < LATE_BUCKETS * this.bucketLen) lead = Math.max(lead, early + this.lead0);
    this.lead = Math.min(lead, early + this.leadMax);
  }

  // The window's smallest and largest lateness, samples.
  window() {
    let early = Infinity, late = -Infinity;
    for (let i = 0; i < LATE_BUCKETS; i++) { early = Math.min(early, this.early[i]); late = Math.max(late, this.late[i]); }
    return [early, late];
  }

  // Everything the ring holds, in the order it was written (route.js's record kinds: 0 sound
  // ticks, 1 restart, 2 finish).
  drain(nowMs) {
    for (let r = this.ring.next(); r !== null; r = this.ring.next()) {
      const [kind, buf] = r;
      if (kind === 0) this.take(buf, nowMs);
      else if (kind === 1) this.restart();
      else if (kind === 2 && buf.byteLength === 8) this.finish(new DataView(buf).getFloat64(0, true));
    }
  }

  process(inputs, outputs) {
    const out = outputs[0][0];
    if (!out) return true;
    if (this.ring !== null) this.drain(Date.now());
    if (!this.offline) this.cadence.quantum(Date.now());
    const r = this.render(out);
    this.clock += out.length;
    return r;
  }

  // Drops the FIFO's first `n` samples (none if `n` ≤ 0): listed and counted as dropped or,
  // when `silent` (all of them 0, between silences), as skipped.
  drop(n, silent) {
    if (n <= 0) return;
    if (this.heard.first < 0) this.heard.first = this.fifo.first; // the stream's first sample
    const list = silent ? this.heard.skips : this.heard.drops;
    if (list.length < 10000) list.push([this.fifo.first, n]);
    this.fifo.drop(n);
    if (silent) this.skipped += n; else this.dropped += n;
  }

  // While the output plays silence, it follows the lead to the sample: where the lead grew
  // past it, it waits (silence, not the session's, not hashed; up to the rest of the quantum
  // from frame `at`) unless a sample queued is about to sound; where the lead fell behind it
  // by at most TRIM_S, it skips the silent samples queued (0, up to the next sound's first
  // sample; further behind, the trim drops the excess, sound or not). Returns the frame the
  // quantum plays the FIFO from.
  follow(out, at) {
    const fifo = this.fifo;
    const behind = this.clock + at - fifo.first - this.lead;
    if (behind < 0) {
      if (fifo.length > 0 && fifo.buf[fifo.head] !== 0) return at;
      const w = Math.min(-behind, out.length - at);
      out.fill(0, at, at + w); this.waited += w;
      return at + w;
    }
    if (behind > this.trim) return at;
    const next = this.onsets.length ? this.onsets[0][0] - fifo.first : Infinity;
    const limit = Math.min(behind, fifo.length, next);
    let z = 0;
    while (z < limit && fifo.buf[fifo.head + z] === 0) z++;
    this.drop(z, true);
    return at;
  }

  // One render quantum into `out`.
  render(out) {
    const fifo = this.fifo;
    if (!this.offline && !this.ending) this.sizeLead();
    // Play once the clock is a lead past the next sample (and a quantum of it is queued):
    // from the frame of this quantum where it is.
    let at = 0;
    if (!this.primed) {
      const wait = this.synth === null ? Infinity : fifo.first + this.lead - this.clock;
      if (wait >= out.length || fifo.length < out.length) { out.fill(0); return true; }
      // A stream's first play with its next sample more than TRIM_S past the lead (its
      // start-up backlog): the samples due before now are dropped, so it starts a lead behind
      // the clock rather than anywhere up to TRIM_S behind it, where the trim would leave it.
      const first = this.heard.first < 0 && !this.offline;
      if (first && wait < -this.trim) this.drop(Math.min(-wait, fifo.length - out.length));
      at = Math.max(0, fifo.first + this.lead - this.clock);
      out.fill(0, 0, at);
      this.primed = true;
      if (first) this.forget();
    }
    // Playing more than TRIM_S behind the lead: drop the excess (keeping a quantum queued at
    // the lowest of the last ~0.1 s of quanta).
    this.minLevel = Math.min(this.minLevel, fifo.length);
    if (++this.quanta >= Math.ceil(0.1 * sampleRate / out.length)) {
      const excess = this.clock - fifo.first - this.lead;
      if (!this.offline && !this.ending && excess > this.trim) {
        // (Never a guessed sample: those played are checked when the ticks come.)
        const n = Math.min(excess, this.minLevel - out.length, this.guess === null ? Infinity : this.guess.from - fifo.first);
        this.drop(n);
      }
      this.minLevel = Infinity; this.quanta = 0;
    }
    if (!this.offline && !this.ending && this.guess === null && this.lastOut === 0) at = this.follow(out, at);
    if (!this.offline && !this.ending && fifo.length < out.length - at) this.extend(out.length - at);
    const from = fifo.first;
    const n = fifo.take(out, at);
    if (!this.offline) this.hear(out, at, n, from);
    this.lastOut = n > 0 ? out[at + n - 1] : 0;
    if (at + n < out.length) {
      out.fill(0, at + n);
      if (this.ending) {
        // The end of the stream, not an underrun.
        if (!this.done) { this.done = true; this.port.postMessage(this.report('done')); }
      } else if (!this.offline) {
        // An underrun: silence, then play again a lead behind the clock (the lead unchanged).
        this.underruns++; this.primed = false;
      }
    }
    // Report the sounds whose first sample is in this quantum (or was dropped).
    if (this.onsets.length && this.onsets[0][0] < from + n) {
      const renderMs = Date.now();
      while (this.onsets.length && this.onsets[0][0] < from + n) {
        const [k, tick, wallMs, gotMs, index] = this.onsets.shift();
        if (k < from) { this.port.postMessage({ kind: 'lost', tick, index }); continue; }
        const frame = at + k - from;
        this.port.postMessage({
          kind: 'onset', tick, index, wallMs, gotMs, renderMs, frame, sampleRate,
          contextTime: currentTime + frame / sampleRate,
          underruns: this.underruns, dropped: this.dropped, skipped: this.skipped, waited: this.waited, limited: this.synth ? this.synth.limited : 0,
          guesses: this.guesses, concealedSamples: this.concealedSamples, level: fifo.length, ...this.leadReport(),
        });
      }
    }
    return true;
  }

  // The lead past the window's earliest arrival and the window's jitter (its largest minus
  // its smallest lateness), ms (null: nothing measured), the render cadence, and the messages'
  // lateness past their window's earliest, ms (p50, p99, p99.9, the largest bin's start).
  leadReport() {
    const [early, late] = this.window();
    const ms = (x) => (Number.isFinite(x) ? x / sampleRate * 1000 : null);
    const sp = this.spread;
    const spread = sp.n ? { ms: [sp.at(0.5), sp.at(0.99), sp.at(0.999), sp.at(1)], messages: sp.n } : null;
    return { leadMs: ms(this.lead - early), jitterMs: ms(late - early), cadence: this.cadence.report(), spread };
  }

  // The counts and what was heard (`kind`: 'done' at the end of the stream).
  report(kind) {
    return {
      kind, sampleRate, underruns: this.underruns, dropped: this.dropped, skipped: this.skipped, waited: this.waited,
      guesses: this.guesses, concealedSamples: this.concealedSamples, limited: this.synth ? this.synth.limited : 0, emitted: this.synth ? this.synth.nextSample : 0,
      ...this.leadReport(), ...this.heard,
    };
  }
}

registerProcessor('nh-synth', Synth);
