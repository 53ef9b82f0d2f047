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

// Sound-ticks messages kept while the synthesis loads.
const WAITING_MAX = 2000;
// The first bytes of a message of each of the types the route looks at, as serde_json writes
// a ServerMsg (`{"type":"hello",...}`: the tag first, no spaces).
const HELLO = '{"type":"hello"', END = '{"type":"end"', LESSON = '{"type":"lesson"';

export class SoundRoute {
  constructor() {
    // 'off' (no audio yet), 'waiting' (the synthesis loads), 'port' (it plays), 'none'
    // (no sound in this browser).
    this.audio = 'off'; this.port = null; this.waiting = [];
    this.lesson = false; this.hello = false;
    // The counts the tests and benches read (window.__play.sound), and what is new in the
    // lists since the last report.
    this.counts = { messages: 0, ticks: 0, sounds: 0, firstTick: -1, nextTick: 0, gaps: 0, restarts: 0 };
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

  // To the synthesis, or kept while it loads (sound ticks up to WAITING_MAX); nothing before
  // the audio opens or when there is none.
  deliver(m, bounded) {
    if (this.audio === 'port') this.port.postMessage(m, m instanceof ArrayBuffer ? [m] : []);
    else if (this.audio === 'waiting' && (!bounded || this.waiting.length < WAITING_MAX)) this.waiting.push(m);
  }

  // The audio opened (the Start press): keep the ticks until the synthesis's port comes.
  audioOn() { if (this.audio === 'off') this.audio = 'waiting'; }

  // The synthesis's port: what waited first, then everything as it comes.
  connect(port) {
    if (this.audio === 'none') return;
    this.port = port; this.audio = 'port';
    for (const m of this.waiting) port.postMessage(m, m instanceof ArrayBuffer ? [m] : []);
    this.waiting = [];
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
