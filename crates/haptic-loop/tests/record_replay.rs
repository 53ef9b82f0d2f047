//! Recording and bit-exact replay: round trips, determinism, divergence reports, damaged files,
//! and the golden recordings under `recordings/`.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use haptic_devices::source::OperatorChoice;
use haptic_loop::replay::verify;
use haptic_loop::session::{SceneSource, SessionArrays, SessionOptions, read_arrays, run_session};
use recording::channels::messages::{
    Channel, DescriptionMsg, DeviceInputMsg, EventsMsg, ForceMsg, StateMsg, SwitchMsg, TimingMsg,
};
use recording::writer::channel_schema;
use recording::{RecordingError, read_recording, read_recording_file};
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn tmp(name: &str) -> PathBuf {
    let d = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("haptic-loop-test-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join(name)
}

fn wall_opts(out: Option<PathBuf>) -> SessionOptions {
    let mut o =
        SessionOptions::new(SceneSource::from_path(&root().join("scenes/wall.toml")).unwrap());
    o.out = out;
    o
}

#[test]
fn recording_replays_bit_exactly_and_reads_back_the_same_arrays() {
    let p = tmp("wall.mcap");
    let report = run_session(&wall_opts(Some(p.clone())), &mut |_, _| {}).unwrap();
    let rec = read_recording_file(&p, false).unwrap();
    let v = verify(&rec).unwrap();
    assert!(v.ok(), "{:?}", v.divergence);
    assert_eq!(v.ticks, 4000);
    // state + force every tick, Foxglove scene + tf at 50 Hz, events and their log lines.
    let events = report.arrays.events.len() as u64;
    let event_ticks = rec
        .messages
        .iter()
        .filter(|m| m.channel == Channel::Events)
        .count() as u64;
    assert_eq!(
        v.messages_compared,
        2 * 4000 + 2 * 200 + event_ticks + events
    );
    let back = read_arrays(&p, false).unwrap();
    assert_eq!(back, report.arrays);
    // The physics the recording shows: the wall is capped at the Falcon's 3000 N/m, the force
    // is clamped at 8 N along +z, and the Foxglove channels use the foxglove schemas.
    let k = back.state_column("stiffness_n_per_m").unwrap();
    assert!(k.iter().all(|&k| k == 3000.0));
    let peak = back.device_force_n.iter().map(|f| f[2]).fold(0.0, f64::max);
    assert_eq!(peak, 8.0);
    assert!(back.events.iter().any(|e| e.1 == "force.clamped"));
    assert!(back.events.iter().any(|e| e.1 == "wall.stiffness_capped"));
    let schemas: Vec<_> = rec.channels.iter().map(|c| c.1.as_str()).collect();
    for s in [
        "foxglove.SceneUpdate",
        "foxglove.FrameTransform",
        "foxglove.Log",
    ] {
        assert!(schemas.contains(&s), "{s} missing from {schemas:?}");
    }
}

#[test]
fn force_feedback_changes_the_simulated_hand_but_not_a_rigid_one() {
    let mut rigid = wall_opts(None);
    rigid.operator = OperatorChoice::Rigid;
    let r = run_session(&rigid, &mut |_, _| {}).unwrap().arrays;
    let h = run_session(&wall_opts(None), &mut |_, _| {})
        .unwrap()
        .arrays;
    // At the deepest scripted point (t = 2.6 s, z = −35 mm) the rigid stylus is at the script;
    // the hand is held up by the wall near k_hand·(z_i − z) = k_wall·d (capped/clamped force).
    let t = 2600;
    assert!((r.device_position_m[t][2] + 0.035).abs() < 1e-12);
    let z = h.device_position_m[t][2];
    assert!(z > -0.0085 && z < -0.005, "hand z = {z}");
    // Equilibrium check: the spring pull of the hand balances the (clamped) wall force.
    let f = h.device_force_n[t][2];
    let pull = 300.0 * (z + 0.035);
    assert!((pull - f).abs() < 0.2, "pull {pull} N vs wall {f} N");
}

#[test]
fn same_inputs_same_bits_across_runs() {
    let a = tmp("det-a.mcap");
    let b = tmp("det-b.mcap");
    // The session's start (wall clock) is part of the recording: pin it.
    let pinned = |p: &PathBuf| {
        let mut o = wall_opts(Some(p.clone()));
        o.start_time_ns = Some(1_795_000_000_000_000_000);
        o
    };
    run_session(&pinned(&a), &mut |_, _| {}).unwrap();
    run_session(&pinned(&b), &mut |_, _| {}).unwrap();
    let ra = read_recording_file(&a, false).unwrap();
    let rb = read_recording_file(&b, false).unwrap();
    let outputs = |r: &recording::Recording| {
        r.messages
            .iter()
            .filter(|m| m.channel != Channel::Timing)
            .map(|m| (m.channel, m.log_time_ns, m.data.clone()))
            .collect::<Vec<_>>()
    };
    assert_eq!(outputs(&ra), outputs(&rb));
}

#[test]
fn divergence_names_the_first_tick_and_channel() {
    let p = tmp("div.mcap");
    run_session(&wall_opts(Some(p.clone())), &mut |_, _| {}).unwrap();
    let rec = read_recording_file(&p, false).unwrap();
    let t0 = rec.description.start_time_ns;

    // A tampered force at tick 1234.
    let mut bad = rec.clone();
    let m = bad
        .messages
        .iter_mut()
        .find(|m| m.channel == Channel::Force && m.log_time_ns == t0 + 1_234_000_000)
        .unwrap();
    let mut f = ForceMsg::decode(&m.data).unwrap();
    f.device_force_n[2] = f64::from_bits(f.device_force_n[2].to_bits() ^ 1);
    m.data = f.encode();
    let d = verify(&bad).unwrap().divergence.unwrap();
    assert_eq!((d.tick, d.channel.as_str()), (1234, "/haptic/force"));
    assert!(d.detail.starts_with("recorded world"), "{}", d.detail);

    // A recorded deadline miss at tick 900 that the recorded outputs do not show.
    let mut bad = rec.clone();
    let m = bad
        .messages
        .iter_mut()
        .find(|m| m.channel == Channel::DeviceInput && m.log_time_ns == t0 + 900_000_000)
        .unwrap();
    let mut i = DeviceInputMsg::decode(&m.data).unwrap();
    i.deadline_missed = true;
    m.data = i.encode();
    let d = verify(&bad).unwrap().divergence.unwrap();
    assert_eq!((d.tick, d.channel.as_str()), (900, "/haptic/force"));

    // A scene edited after recording: the wall's damping doubled. Nothing differs until the
    // first tick of contact, where the damping term first acts on the force.
    let a = SessionArrays::from_recording(&rec).unwrap();
    let contact = a.state_column("in_contact").unwrap();
    let first = contact.iter().position(|&c| c == 1.0).unwrap() as u64;
    let mut bad = rec.clone();
    bad.description.scene_toml = bad
        .description
        .scene_toml
        .replace("damping_n_s_per_m = 1.0", "damping_n_s_per_m = 2.0");
    let d = verify(&bad).unwrap().divergence.unwrap();
    assert_eq!((d.tick, d.channel.as_str()), (first, "/haptic/force"));
    // The wall moved by 1 mm: the drawn scene differs from tick 0.
    let mut bad = rec.clone();
    bad.description.scene_toml = bad.description.scene_toml.replace(
        "point_m = [0.0, 0.0, -0.005]",
        "point_m = [0.0, 0.0, -0.006]",
    );
    let d = verify(&bad).unwrap().divergence.unwrap();
    assert_eq!((d.tick, d.channel.as_str()), (0, "/foxglove/scene"));
    // A dropped events message.
    let mut bad = rec.clone();
    let k = bad
        .messages
        .iter()
        .position(|m| m.channel == Channel::Events)
        .unwrap();
    let t = (bad.messages[k].log_time_ns - t0) / 1_000_000;
    bad.messages.remove(k);
    let d = verify(&bad).unwrap().divergence.unwrap();
    assert_eq!(d.tick, t);
    assert_eq!(d.detail, "replay produced a message that was not recorded");
}

#[test]
fn damaged_files_give_clear_errors() {
    let p = tmp("dmg.mcap");
    // A pinned start makes the file the same bytes every run, so the flips below are too.
    let mut o = wall_opts(Some(p.clone()));
    o.start_time_ns = Some(1_795_000_000_000_000_000);
    run_session(&o, &mut |_, _| {}).unwrap();
    let bytes = std::fs::read(&p).unwrap();

    assert_eq!(
        read_recording(b"hello, world", false).unwrap_err(),
        RecordingError::NotMcap
    );

    // Truncated mid-file: an error that says how much is readable; salvage replays that part.
    let cut = &bytes[..bytes.len() * 2 / 3];
    match read_recording(cut, false).unwrap_err() {
        RecordingError::Truncated { ticks, .. } => assert!((1000..4000).contains(&ticks)),
        e => panic!("expected Truncated, got {e}"),
    }
    let part = read_recording(cut, true).unwrap();
    assert!(part.truncated.is_some());
    let v = verify(&part).unwrap();
    assert!(v.ok(), "{:?}", v.divergence);
    // Chunks are flushed every second of session time, so the salvaged ticks are whole seconds.
    assert_eq!(v.ticks % 1000, 0);

    // A damaged uncompressed-size field of a chunk (issue 11 item 16: it used to abort every
    // reader with "memory allocation of 378486468177297417 bytes failed") is a typed error.
    let mut at = 8;
    while bytes[at] != 0x06 {
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap()) as usize;
        at += 9 + len;
    }
    let mut huge = bytes.clone();
    huge[at + 9 + 16..at + 9 + 24].copy_from_slice(&378_486_468_177_297_417u64.to_le_bytes());
    let e = read_recording(&huge, false).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!(
            "corrupt recording: chunk at byte {at}: uncompressed size 378486468177297417 bytes"
        )),
        "{e}"
    );
}

#[test]
fn golden_recordings_replay_bit_exactly() {
    let dir = root().join("recordings");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_some_and(|x| x == "mcap") {
            let rec = read_recording_file(&p, false).unwrap();
            let v = verify(&rec).unwrap();
            assert!(v.ok(), "{}: {:?}", p.display(), v.divergence);
            assert!(v.ticks > 0);
            let a = SessionArrays::from_recording(&rec).unwrap();
            assert_eq!(a.tick.len() as u64, v.ticks);
            n += 1;
        }
    }
    assert!(n >= 1, "no golden recordings in {}", dir.display());
}

/// A recording's timeline is its session's: every message, the description included, lies
/// between the session's start and its last tick, so the file's statistics (what Foxglove's
/// timeline shows) span the session and not the decades since 1970.
#[test]
fn the_timeline_of_a_recording_is_its_session() {
    let out = tmp("timeline.mcap");
    let mut o = wall_opts(Some(out.clone()));
    let t0 = 1_795_577_000_000_000_000;
    o.start_time_ns = Some(t0);
    o.seconds = Some(0.25);
    run_session(&o, &mut |_, _| {}).unwrap();
    let buf = std::fs::read(&out).unwrap();
    let stats = mcap::Summary::read(&buf).unwrap().unwrap().stats.unwrap();
    // 250 ticks at 1 kHz: the last is tick 249, 249 ms after the start.
    assert_eq!(stats.message_start_time, t0);
    assert_eq!(stats.message_end_time, t0 + 249_000_000);
    let rec = read_recording(&buf, false).unwrap();
    let desc = rec
        .messages
        .iter()
        .find(|m| m.channel == Channel::Description)
        .unwrap();
    assert_eq!(desc.log_time_ns, t0);
    assert!(verify(&rec).unwrap().ok());
}

/// The schemas written today (from the channel declarations) are, byte for byte, the schemas
/// stored in every golden recording, channel by channel, with the same ids and encodings.
#[test]
fn golden_recordings_hold_the_schemas_the_declarations_write() {
    let dir = root().join("recordings");
    let mut n = 0;
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "mcap") {
            continue;
        }
        let buf = std::fs::read(&p).unwrap();
        let rec = read_recording(&buf, false).unwrap();
        let summary = mcap::Summary::read(&buf).unwrap().unwrap();
        assert_eq!(summary.channels.len(), Channel::COUNT, "{}", p.display());
        // The golden's timeline is its session's (the description at the start time).
        let stats = summary.stats.as_ref().unwrap();
        assert_eq!(
            stats.message_start_time,
            rec.description.start_time_ns,
            "{}",
            p.display()
        );
        for (k, ch) in Channel::ALL.into_iter().enumerate() {
            let c = summary
                .channels
                .values()
                .find(|c| c.topic == ch.topic())
                .unwrap_or_else(|| panic!("{}: no {}", p.display(), ch.topic()));
            // Channels and schemas are registered in declaration order (ids from 1).
            assert_eq!(usize::from(c.id), k + 1, "{}", ch.topic());
            assert_eq!(c.message_encoding, ch.message_encoding(), "{}", ch.topic());
            let stored = c.schema.as_ref().unwrap();
            assert_eq!(usize::from(stored.id), k + 1, "{}", ch.topic());
            let (name, enc, data) = channel_schema(ch, &rec.description);
            assert_eq!(
                (stored.name.as_str(), stored.encoding.as_str()),
                (name.as_str(), enc.as_str()),
                "{}: {}",
                p.display(),
                ch.topic()
            );
            assert!(
                stored.data.as_ref() == data.as_slice(),
                "{}: the {} schema differs from the declaration's:\n{}\n--- declared:\n{}",
                p.display(),
                ch.topic(),
                String::from_utf8_lossy(&stored.data),
                String::from_utf8_lossy(&data)
            );
        }
        n += 1;
    }
    // brickworld (the script's whole session under the default solver, 4 iterations at 500 Hz),
    // brickworld_shipped (its first 4 s under the scene file as shipped: 1 iteration at
    // 175 Hz), nanoworld, optical_tweezers, wall.
    assert_eq!(n, 5, "golden recordings in {}", dir.display());
}

/// Every CDR message of every golden recording, decoded with the declared decoder and encoded
/// again with the declared encoder, gives back its recorded bytes (inputs, description and
/// timing included, which replay does not recompute).
#[test]
fn golden_messages_reencode_to_their_recorded_bytes() {
    let dir = root().join("recordings");
    let mut per_channel = std::collections::BTreeMap::new();
    for e in std::fs::read_dir(&dir).unwrap() {
        let p = e.unwrap().path();
        if p.extension().is_none_or(|x| x != "mcap") {
            continue;
        }
        let rec = read_recording_file(&p, false).unwrap();
        let n = rec.description.state_fields.len();
        for m in &rec.messages {
            let d = &m.data;
            let again = match m.channel {
                Channel::Description => DescriptionMsg::decode(d).unwrap().encode(),
                Channel::DeviceInput => DeviceInputMsg::decode(d).unwrap().encode(),
                Channel::Switch => SwitchMsg::decode(d).unwrap().encode(),
                Channel::State => StateMsg::decode(d, n).unwrap().encode(),
                Channel::Force => ForceMsg::decode(d).unwrap().encode(),
                Channel::Events => EventsMsg::decode(d).unwrap().encode(),
                Channel::Timing => TimingMsg::decode(d).unwrap().encode(),
                Channel::FoxgloveScene | Channel::FoxgloveTf | Channel::FoxgloveLog => continue,
            };
            assert!(
                again == *d,
                "{}: a {} message at {} ns re-encodes differently",
                p.display(),
                m.channel.topic(),
                m.log_time_ns
            );
            *per_channel.entry(m.channel.topic()).or_insert(0u64) += 1;
        }
    }
    // Every CDR channel but `/scene/switch` (no golden session sets a switch) was exercised.
    let topics: Vec<&str> = per_channel.keys().copied().collect();
    assert_eq!(
        topics,
        [
            "/device/input",
            "/events",
            "/haptic/force",
            "/loop/timing",
            "/scene/description",
            "/world/state"
        ]
    );
}

#[test]
fn realtime_session_replays_exactly_including_its_missed_deadlines() {
    let p = tmp("rt.mcap");
    let mut o = wall_opts(Some(p.clone()));
    o.realtime = true;
    o.seconds = Some(0.5);
    let report = run_session(&o, &mut |_, _| {}).unwrap();
    let a = &report.arrays;
    assert_eq!(a.tick.len(), 500);
    assert_eq!(a.start_late_ns.len(), 500);
    assert!(a.start_late_ns.iter().all(|&l| l >= 0));
    // Whatever the machine did, each missed deadline is logged as an input, flagged in the
    // status, and sent zero force; replay reproduces the session bit for bit.
    let missed: Vec<usize> = (0..500).filter(|&i| a.deadline_missed[i]).collect();
    assert_eq!(missed.len() as u64, report.stats.missed);
    for &i in &missed {
        assert!(a.status[i] & 4 != 0);
        assert_eq!(a.device_force_n[i], [0.0; 3]);
    }
    assert_eq!(
        a.status.iter().filter(|s| **s & 4 != 0).count(),
        missed.len()
    );
    let v = verify(&read_recording_file(&p, false).unwrap()).unwrap();
    assert!(v.ok(), "{:?}", v.divergence);
}

#[test]
fn touch_device_caps_at_its_own_limits() {
    let mut o = wall_opts(None);
    o.device = Some(haptic_devices::source::DeviceSource::Model(
        haptic_types::DeviceModel::Touch,
    ));
    o.operator = OperatorChoice::Rigid;
    o.script = Some(
        "[script]\nname = 'ramp'\n[[waypoint]]\nt_s = 0.0\nposition_mm = [0.0, 0.0, 0.0]\n\
         [[waypoint]]\nt_s = 2.0\nposition_mm = [0.0, 0.0, -30.0]\n"
            .to_string(),
    );
    let a = run_session(&o, &mut |_, _| {}).unwrap().arrays;
    // The scene is written for a Falcon (3000 N/m): on a Touch (400 N/m) its mapping is
    // fitted (issue 31), so the wall keeps the stiffness it has on a Falcon in the world and
    // reaches the device at the Touch's 400 N/m, said by a `device.fit` event at tick 0.
    assert!(
        a.state_column("stiffness_n_per_m")
            .unwrap()
            .iter()
            .all(|&k| k == 3000.0)
    );
    let kz = a
        .device_stiffness_n_per_m
        .iter()
        .map(|k| k[8])
        .fold(0.0, f64::max);
    assert!((kz - 400.0).abs() < 1e-9, "{kz}");
    let fit: Vec<_> = a.events.iter().filter(|e| e.1 == "device.fit").collect();
    assert_eq!(fit.len(), 1);
    assert_eq!(fit[0].0, 0);
    assert_eq!(
        fit[0].2,
        "mapping.force_scale 1 → 0.13333333333333333 (×0.13333333333333333): touch renders up \
         to 400 N/m, the scene is written for falcon (3000 N/m); every world stiffness, damping \
         and force reaches the device ×0.13333333333333333 (set mapping.fit_device = false to \
         refuse instead)"
    );
    let peak = a
        .device_force_n
        .iter()
        .map(|f| (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt())
        .fold(0.0, f64::max);
    assert_eq!(peak, 3.3);
    // A script binds its button events by role: on a Touch the wall script's grip is
    // button1; its turn_x (a Falcon's plus) has no button there and is left out. A script
    // naming a Falcon button is still refused on a Touch, by name.
    let wall = std::fs::read_to_string(root().join("scenes/wall.script.toml")).unwrap();
    let touch = haptic_types::DeviceModel::Touch.specs();
    let s = haptic_devices::Script::from_toml(&wall, touch).unwrap();
    assert_eq!(
        s.buttons
            .iter()
            .map(|b| (b.index, b.down))
            .collect::<Vec<_>>(),
        [(0, true), (0, false)]
    );
    let e = haptic_devices::Script::from_toml(
        &wall.replacen("role = \"grip\"", "name = \"centre\"", 1),
        touch,
    );
    assert_eq!(
        e.unwrap_err().to_string(),
        "script: `button[0].name`: device `touch` has no button `centre` (allowed: button1, \
         button2)"
    );
}

#[test]
fn an_unwritable_recording_path_is_a_typed_error() {
    let o = wall_opts(Some(PathBuf::from("/nonexistent-dir/x.mcap")));
    let e = run_session(&o, &mut |_, _| {}).unwrap_err();
    assert_eq!(
        e.to_string(),
        "recording /nonexistent-dir/x.mcap: No such file or directory (os error 2)"
    );
}

/// Without a recording nothing is encoded: the arrays are the only sink besides the running
/// totals (filled straight from
/// each tick), and they equal, column by column, what a recorded run of the same session reads
/// back from its file (bar the wall-clock columns).
#[test]
fn an_unrecorded_session_runs_only_the_arrays_and_matches_its_recording() {
    let mut o = wall_opts(None);
    o.seconds = Some(2.0);
    o.start_time_ns = Some(1_700_000_000_000_000_000);
    let plain = run_session(&o, &mut |_, _| {}).unwrap();
    let sinks: Vec<&str> = plain.sinks.iter().map(|s| s.sink).collect();
    assert_eq!(sinks, ["totals", "arrays"]);
    // The running totals (what `nanohaptics run` summarises, in constant memory) are the
    // arrays' own figures.
    let (t, a) = (&plain.totals, &plain.arrays);
    let peak = a
        .device_force_n
        .iter()
        .map(|f| (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt())
        .fold(0.0, f64::max);
    assert!(peak > 0.5, "the wall press pushes back: {peak} N");
    assert_eq!(t.peak_device_force_n, peak);
    assert_eq!(t.ticks, 2000);
    assert_eq!(t.events, a.events.len() as u64);
    assert_eq!(
        t.clamped_ticks,
        a.status.iter().filter(|s| **s & 1 != 0).count() as u64
    );
    assert_eq!(
        t.watchdog_ticks,
        a.status.iter().filter(|s| **s & 32 != 0).count() as u64
    );
    let n = t.state_fields.len();
    assert!(n > 0);
    assert_eq!(t.last_state[..], a.state[a.state.len() - n..]);
    let p = tmp("wall-two-seconds.mcap");
    o.out = Some(p.clone());
    let recorded = run_session(&o, &mut |_, _| {}).unwrap();
    let sinks: Vec<&str> = recorded.sinks.iter().map(|s| s.sink).collect();
    assert_eq!(sinks, ["totals", "arrays", "recorder"]);
    let back = read_arrays(&p, false).unwrap();
    assert_eq!(back, recorded.arrays);
    assert_eq!(plain.arrays.tick.len(), 2000);
    let (a, b) = (plain.arrays.columns(), back.columns());
    assert_eq!(a.len(), b.len());
    for ((info, x), (_, y)) in a.into_iter().zip(b) {
        if !["compute_ns", "start_late_ns"].contains(&info.name) {
            assert_eq!(x, y, "{}", info.name);
        }
    }
    assert_eq!(plain.arrays.events, back.events);
    assert_eq!(plain.arrays.state_fields, back.state_fields);
}
