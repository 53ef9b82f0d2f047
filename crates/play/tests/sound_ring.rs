//! The sound ring (route.js's `SoundRing`, synth.js's `RingReader`): the shared memory through
//! which the page's link worker hands the server's sound ticks to the AudioWorklet, read at the
//! start of each render quantum. Driven in a real page (the play server's, cross-origin
//! isolated by its headers, so `SharedArrayBuffer` exists) with no socket and no clock: the
//! ring carries what the worklet's port would, record for record, in the same order; records
//! wrap around its end; a full ring keeps the ticks waiting, in order, up to the route's bound,
//! and counts the ones beyond it; the worklet reads the ring before it renders.
//!
//! `cargo test --release -p nanohaptics-play --test sound_ring` (Debian's `chromium`).

#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;

use common::page::{PageServer, block};
use play::protocol::ServerMsg;
use serde_json::json;

/// The page's JavaScript that the tests share: the route's and the reader's classes, the
/// blocks, and `drain(reader)`, every record the reader holds described as the port test
/// describes a message (`ticks N` by its first tick, else the message's JSON).
fn prelude() -> String {
    format!(
        r#"
  const {{ SoundRoute }} = await import('/route.js');
  const src = await (await fetch('/synth.js')).text();
  globalThis.sampleRate = 44100; globalThis.currentTime = 0;
  globalThis.AudioWorkletProcessor = class {{
    constructor() {{ this.port = {{ postMessage: (m) => reports.push(m), onmessage: null }}; }}
  }};
  let Proc = null;
  globalThis.registerProcessor = (name, cls) => {{ Proc = cls; }};
  const reports = [];
  const RingReader = new Function(src + '; return RingReader;')();
  const ab = (s) => Uint8Array.from(atob(s), (c) => c.charCodeAt(0)).buffer;
  const [A, B, C, D] = [{a}, {b}, {c}, {d}];
  const describe = ([kind, buf]) => kind === 0 ? `ticks ${{Number(new DataView(buf).getBigUint64(0, true))}}`
    : kind === 1 ? JSON.stringify({{ restart: true }}) : JSON.stringify({{ finish: new DataView(buf).getFloat64(0, true) }});
  const drain = (reader) => {{ const got = []; for (let r = reader.next(); r !== null; r = reader.next()) got.push(describe(r)); return got; }};
"#,
        a = json!(block(0, &[1000.0, 1001.0], &[[1, 0]])),
        b = json!(block(2, &[1002.0, 1003.0], &[])),
        c = json!(block(0, &[2000.0, 2001.0], &[[0, 0]])),
        d = json!(block(5, &[1005.0], &[])),
    )
}

/// A lesson's two worlds, as the port's test plays them (browser_sound.rs,
/// `the_links_route_keeps_restarts_and_finishes_in_the_order_of_the_ticks`), through a ring:
/// the same five records in the same order, each tick message's bytes as the server sent them.
#[test]
fn the_ring_carries_what_the_port_would_in_the_same_order() {
    let (mut b, server) = PageServer::open("nh-sound-ring.mcap");
    let msgs = ServerMsg::examples();
    let [hello, frame, stopped, lesson] = [0, 3, 6, 7].map(|i| msgs[i].to_json());
    let ServerMsg::End(mut e) = msgs[6].clone() else {
        panic!("the sixth example is an end")
    };
    e.end = haptic_engine::runner::EndReason::Completed;
    e.ticks = 4;
    let completed = ServerMsg::End(e).to_json();
    let js = format!(
        r#"(async () => {{
  {prelude}
  const [hello, frame, stopped, lesson, completed] = [{hello}, {frame}, {stopped}, {lesson}, {completed}];
  const isolated = globalThis.crossOriginIsolated;
  const sab = new SharedArrayBuffer(8 + 4096), reader = new RingReader(sab);
  const r = new SoundRoute();
  r.text(lesson); r.text(hello); r.binary(ab(A), 1005);
  r.audioOn();
  r.binary(ab(B), 1010); r.text(frame);
  r.connectRing(sab);
  const first = drain(reader);
  r.text(completed); r.text(lesson); r.text(hello); r.binary(ab(C), 2003); r.text(stopped);
  // The tick message's bytes, as sent.
  const r2 = new SoundRoute(), sab2 = new SharedArrayBuffer(8 + 4096);
  r2.audioOn(); r2.connectRing(sab2); r2.binary(ab(C), 0);
  const [kind, buf] = new RingReader(sab2).next();
  const same = kind === 0 && btoa(String.fromCharCode(...new Uint8Array(buf))) === {c};
  return {{ isolated, first, rest: drain(reader), same, counts: r.report() }};
}})()"#,
        prelude = prelude(),
        hello = json!(hello),
        frame = json!(frame),
        stopped = json!(stopped),
        lesson = json!(lesson),
        completed = json!(completed),
        c = json!(block(0, &[2000.0, 2001.0], &[[0, 0]])),
    );
    let v = b.eval(&js).unwrap();
    assert_eq!(v["isolated"], true);
    // B waited for the ring and came first; the rest as the port has them.
    assert_eq!(v["first"], json!(["ticks 2"]));
    assert_eq!(
        v["rest"],
        json!([
            r#"{"finish":4}"#,
            r#"{"restart":true}"#,
            "ticks 0",
            r#"{"finish":2}"#
        ])
    );
    assert_eq!(v["same"], true);
    assert_eq!(v["counts"]["overflow"], 0);
    assert_eq!(v["counts"]["messages"], 3);
    b.check().unwrap();
    server.close();
}

/// A ring of 199 bytes of room holds three 64-byte tick records: the fourth and fifth wait;
/// the reader's room lets the route's flush write them, across the ring's end; every record
/// comes out once, in order. Full with 2000 waiting, the next tick message is counted in
/// `overflow` (and not kept); the finish after it still waits, and comes last. A tick message
/// larger than the whole ring is counted and holds up nothing behind it.
#[test]
fn a_full_ring_keeps_the_order_and_counts_what_it_could_not_keep() {
    let (mut b, server) = PageServer::open("nh-sound-ring-full.mcap");
    let blocks: Vec<String> = (0..5)
        .map(|k| block(2 * k, &[1000.0, 1001.0], &[]))
        .collect();
    let js = format!(
        r#"(async () => {{
  {prelude}
  const blocks = {blocks}.map(ab);
  const sab = new SharedArrayBuffer(8 + 200), reader = new RingReader(sab);
  const r = new SoundRoute();
  r.audioOn(); r.connectRing(sab);
  for (const m of blocks.slice(0, 5)) r.binary(m.slice(0), 0);
  const waited = r.waiting.length;
  const some = [reader.next(), reader.next()].map(describe);
  r.flush();
  const wrote = Atomics.load(new Int32Array(sab, 0, 2), 0);
  const rest = drain(reader);
  // 3 in the ring, 2000 waiting, 1 more counted, a finish after it.
  const r2 = new SoundRoute(), sab2 = new SharedArrayBuffer(8 + 200), reader2 = new RingReader(sab2);
  r2.audioOn(); r2.connectRing(sab2);
  for (let i = 0; i < 2004; i++) r2.binary(blocks[0].slice(0), 0);
  r2.finish(7);
  const counted = r2.report().overflow;
  let ticks = 0, last = null;
  for (let k = 0; k < 10000 && last !== '{{"finish":7}}'; k++) {{
    for (const d of drain(reader2)) {{ if (d.startsWith('ticks')) ticks++; last = d; }}
    r2.flush();
  }}
  // A message larger than the whole ring is counted and holds up nothing behind it.
  const r3 = new SoundRoute(), sab3 = new SharedArrayBuffer(8 + 40), reader3 = new RingReader(sab3);
  r3.audioOn(); r3.binary(blocks[0].slice(0), 0); r3.binary(blocks[1].slice(0), 0); r3.finish(4);
  r3.connectRing(sab3);
  const huge = [r3.report().overflow, drain(reader3)];
  return {{ waited, some, wrote, rest, counted, ticks, last, huge }};
}})()"#,
        prelude = prelude(),
        blocks = json!(blocks),
    );
    let v = b.eval(&js).unwrap();
    assert_eq!(v["waited"], 2);
    assert_eq!(v["some"], json!(["ticks 0", "ticks 2"]));
    // Five 64-byte records from offset 0 in a 200-byte ring end at 320 − 200.
    assert_eq!(v["wrote"], 120);
    assert_eq!(v["rest"], json!(["ticks 4", "ticks 6", "ticks 8"]));
    assert_eq!(v["counted"], 1);
    assert_eq!(v["ticks"], 2003);
    assert_eq!(v["last"], r#"{"finish":7}"#);
    // A ring of 39 bytes of room never holds a 64-byte tick record: both are counted, and
    // the 16-byte finish behind them still comes.
    assert_eq!(v["huge"], json!([2, [r#"{"finish":4}"#]]));
    b.check().unwrap();
    server.close();
}

/// The worklet reads its ring before it renders: given the ring, two tick messages and a
/// finish written to it reach the synthesis on the next render quantum, and the stream ends
/// there with a `done` report that heard its 4 ticks' samples, as the port's messages would.
#[test]
fn the_worklet_reads_its_ring_before_each_render_quantum() {
    let (mut b, server) = PageServer::open("nh-sound-ring-worklet.mcap");
    let js = format!(
        r#"(async () => {{
  {prelude}
  const sab = new SharedArrayBuffer(8 + 4096);
  const route = new SoundRoute(); route.audioOn(); route.connectRing(sab);
  const viaRing = new Proc({{ processorOptions: {{ rateHz: 1000, leadS: 0.008, leadMaxS: 0.03 }} }});
  viaRing.port.onmessage({{ data: {{ ring: sab }} }});
  const mine = reports.length;
  route.binary(ab(A), 0); route.binary(ab(B), 0); route.finish(4);
  const before = viaRing.synth === null;
  const out = new Float32Array(128);
  viaRing.process([], [[out]]);
  const ticks = viaRing.synth.ticks;
  for (let q = 0; q < 100 && !viaRing.done; q++) viaRing.process([], [[out]]);
  const ringDone = reports.slice(mine).find((m) => m.kind === 'done');
  // The same through the port.
  const viaPort = new Proc({{ processorOptions: {{ rateHz: 1000, leadS: 0.008, leadMaxS: 0.03 }} }});
  const from = reports.length;
  viaPort.port.onmessage({{ data: ab(A) }}); viaPort.port.onmessage({{ data: ab(B) }});
  viaPort.port.onmessage({{ data: {{ finish: 4 }} }});
  for (let q = 0; q < 100 && !viaPort.done; q++) viaPort.process([], [[out]]);
  const portDone = reports.slice(from).find((m) => m.kind === 'done');
  return {{ before, ticks, ring: [ringDone.played, ringDone.hash, ringDone.emitted], port: [portDone.played, portDone.hash, portDone.emitted] }};
}})()"#,
        prelude = prelude(),
    );
    let v = b.eval(&js).unwrap();
    assert_eq!(v["before"], true);
    assert_eq!(v["ticks"], 4);
    // 4 ticks of 1 ms at 44.1 kHz: 176.4 samples, the stream's 176 (StreamSynth::finish).
    assert_eq!(v["ring"][2], 176);
    assert_eq!(v["ring"][0], 176);
    assert_eq!(v["ring"], v["port"]);
    b.check().unwrap();
    server.close();
}
