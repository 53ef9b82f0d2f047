// nanohaptics play: where the link's messages go, in the order they arrive (the link worker,
// link.js, runs it; no socket, no clock, no DOM, so a test can drive it). The server's binary
// sound ticks (protocol/sound.rs's SoundTicks) are counted and go straight to the synthesis
// (synth.js) through its port; the server's text messages go to the page's main thread, and
// two of them also tell the synthesis where a stream starts and ends, on the same port as the
// ticks and so in the same order as the server sent them: a lesson's next world (a `hello`
// after a `lesson` and an earlier `hello`) restarts it at tick 0 (`{ restart: true }`); an `end`
// finishes it (`{ finish: ticks }`) after the step's own ticks when a lesson's step completed,
// else after the last tick the page heard. Until the audio opens (the Start press) the ticks
// are not kept; while the synthesis loads they wait (at most WAITING_MAX messages).

// Sound-ticks messages kept while the synthesis loads (or while its ring is full).
const WAITING_MAX = 2000;
// The kinds of a ring's records (synth.js's RingReader reads them): a sound-ticks message, a
// restart, a finish (its payload the ticks, an f64).
const RING_TICKS = 0, RING_RESTART = 1, RING_FINISH = 2;

// The sound ring's writing end (the reading end is synth.js's RingReader): a
// SharedArrayBuffer the link worker writes and the worklet reads at the start of each render
// quantum, so a sound tick reaches the synthesis without a task on the audio thread (a
// message on its port waits for the thread's next task, after a burst of quanta it renders
// back to back). Its layout: two Int32 offsets into the data, where the writer writes next and
// where the reader reads next (equal: empty; the writer leaves one byte free), then the data,
// a byte ring of records: the payload's length (u32), the kind (u32), the payload.
export class SoundRing {
  constructor(sab) {
    this.at = new Int32Array(sab, 0, 2);
    this.data = new Uint8Array(sab, 8);
    this.cap = this.data.length;
  }

  // Writes one record of `kind` with payload `bytes` (a Uint8Array); false, writing nothing,
  // when it does not fit.
  write(kind, bytes) {
    const w = Atomics.load(this.at, 0), r = Atomics.load(this.at, 1);
    const used = (w - r + this.cap) % this.cap;
    if (8 + bytes.length > this.cap - 1 - used) return false;
    const head = new Uint8Array(8), dv = new DataView(head.buffer);
    dv.setUint32(0, bytes.length, true); dv.setUint32(4, kind, true);
    const end = this.put(bytes, this.put(head, w));
    // The offset is stored last: the reader sees a record whole or not at all.
    Atomics.store(this.at, 0, end);
    return true;
  }

  // Whether a record of `n` payload bytes fits in the ring when it is empty.
  holds(n) { return 8 + n <= this.cap - 1; }

  put(src, at) {
    const first = Math.min(src.length, this.cap - at);
    this.data.set(src.subarray(0, first), at);
    if (first < src.length) this.data.set(src.subarray(first), 0);
    return (at + src.length) % this.cap;
  }
}

// A message for the synthesis as a ring record [kind, payload].
function record(m) {
  if (m instanceof ArrayBuffer) return [RING_TICKS, new Uint8Array(m)];
  if (m.restart) return [RING_RESTART, new Uint8Array(0)];
  const b = new Uint8Array(8);
  new DataView(b.buffer).setFloat64(0, m.finish, true);
  return [RING_FINISH, b];
}
// The first bytes of a message of each of the types the route looks at, as serde_json writes
// a ServerMsg (`{"type":"hello",...}`: the tag first, no spaces).
const HELLO = '{"type":"hello"', END = '{"type":"end"', LESSON = '{"type":"lesson"';

export class SoundRoute {
  constructor() {
    // 'off' (no audio yet), 'waiting' (the synthesis loads), 'port' or 'ring' (it plays, fed
    // through its port or its ring), 'none' (no sound in this browser).
    this.audio = 'off'; this.port = null; this.ring = null; this.waiting = [];
    this.lesson = false; this.hello = false;
    // The counts the tests and benches read (window.__play.sound), and what is new in the
    // lists since the last report.
    this.counts = { messages: 0, ticks: 0, sounds: 0, firstTick: -1, nextTick: 0, gaps: 0, restarts: 0, overflow: 0 };
    this.sent = []; this.linkMs = []; this.kept = 0; this.timed = 0; this.dirty = false;
  }

  // One binary sound-ticks message `buf` (an ArrayBuffer) that reached the link at `nowMs`
  // (Date.now()): counted, then to the synthesis. Returns the wall time (ms) of the tick of
  // its first sound, or null when it has none.
  binary(buf, nowMs) {
    const c = this.counts;
    let stamp = null;
    if (buf.byteLength >= 24) {
      const dv = new DataView(buf);
      const first = Number(dv.getBigUint64(0, true));
      if (c.firstTick < 0) c.firstTick = first;
      else if (first !== c.nextTick) c.gaps++;
      const nt = dv.getUint32(16, true), ns = dv.getUint32(20, true);
      c.nextTick = first + nt; c.ticks += nt; c.sounds += ns;
      // Each sound: its tick (u64) and its index in the session's list (u32).
      for (let j = 0, at = 24 + 16 * nt; j < ns && at + 24 <= buf.byteLength && this.kept < 100000; j++, at += 24) {
        const tick = Number(dv.getBigUint64(at, true));
        this.sent.push([tick, dv.getUint32(at + 8, true)]); this.kept++;
        // Tick → the link has it, ms (the first sound's).
        const i = tick - first;
        if (j === 0 && i >= 0 && i < nt) {
          stamp = dv.getFloat64(24 + 16 * i, true);
          if (this.timed < 100000) { this.linkMs.push(nowMs - stamp); this.timed++; }
        }
      }
    }
    c.messages++; this.dirty = true;
    this.deliver(buf, true);
    return stamp;
  }

  // One text message `s`: whether it starts or ends a stream. Returns true for the types
  // whose handling on the page reads the counts (hello, end, lesson): the link reports them
  // first.
  text(s) {
    if (s.startsWith(LESSON)) { this.lesson = true; return true; }
    if (s.startsWith(HELLO)) {
      // A lesson's next world: its ticks (and its sound's) start again at 0.
      if (this.lesson && this.hello) this.restart();
      this.hello = true;
      return true;
    }
    if (s.startsWith(END)) {
      const m = JSON.parse(s);
      // A lesson's step completed: its world's ticks; a session (or a lesson) stopped: what
      // the page heard.
      this.finish(this.lesson && m.end === 'completed' ? m.ticks : this.counts.nextTick);
      return true;
    }
    return false;
  }

  restart() {
    this.counts.restarts++; this.counts.nextTick = 0; this.dirty = true;
    this.deliver({ restart: true }, false);
  }

  finish(ticks) { this.deliver({ finish: ticks }, false); }

  // To the synthesis, or kept while it loads or its ring is full (sound ticks up to
  // WAITING_MAX; a sound tick beyond is counted in `overflow`); nothing before the audio
  // opens or when there is none.
  deliver(m, bounded) {
    if (this.audio === 'off' || this.audio === 'none') return;
    if (this.audio === 'port') { this.port.postMessage(m, m instanceof ArrayBuffer ? [m] : []); return; }
    if (this.audio === 'ring' && this.flush() && this.put(m)) return;
    if (!bounded || this.waiting.length < WAITING_MAX) this.waiting.push(m);
    else this.overflow();
  }

  // What waited, into the ring while it fits; true when nothing waits. The link calls it on
  // its timer too, so what waited goes on when no more ticks come.
  flush() {
    if (this.audio !== 'ring') return this.waiting.length === 0;
    let n = 0;
    while (n < this.waiting.length && this.put(this.waiting[n])) n++;
    if (n > 0) this.waiting.splice(0, n);
    return this.waiting.length === 0;
  }

  // `m` into the ring: true when written, or when it could never fit (counted in `overflow`,
  // so it holds up nothing behind it); false when the ring is too full for it now.
  put(m) {
    const [kind, bytes] = record(m);
    if (!this.ring.holds(bytes.length)) { this.overflow(); return true; }
    return this.ring.write(kind, bytes);
  }

  overflow() { this.counts.overflow++; this.dirty = true; }

  // The audio opened (the Start press): keep the ticks until the synthesis's port comes.
  audioOn() { if (this.audio === 'off') this.audio = 'waiting'; }

  // The synthesis's port: what waited first, then everything as it comes.
  connect(port) {
    if (this.audio === 'none') return;
    this.port = port; this.audio = 'port';
    for (const m of this.waiting) port.postMessage(m, m instanceof ArrayBuffer ? [m] : []);
    this.waiting = [];
  }

  // The synthesis's ring (a SharedArrayBuffer, SoundRing's layout): what waited first, then
  // everything as it comes.
  connectRing(sab) {
    if (this.audio === 'none') return;
    this.ring = new SoundRing(sab); this.audio = 'ring';
    this.flush();
  }

  // No sound in this browser: nothing is kept.
  audioNone() { this.audio = 'none'; this.waiting = []; }

  // The counts and the lists' new entries since the last report, or null when nothing changed.
  report() {
    if (!this.dirty) return null;
    const r = { ...this.counts, sent: this.sent, linkMs: this.linkMs };
    this.sent = []; this.linkMs = []; this.dirty = false;
    return r;
  }
}
