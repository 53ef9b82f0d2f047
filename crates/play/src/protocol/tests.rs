//! The protocol's messages: parsing, checking and their wire forms.

use super::*;
use haptic_engine::runner::EndReason;
use serde_json::Value;

fn err(text: &str) -> String {
    parse(text, 0b1111).unwrap_err().to_string()
}

#[test]
fn good_messages_parse() {
    assert_eq!(parse(r#"{"type":"start"}"#, 1), Ok(PageMsg::Start));
    assert_eq!(parse(r#"{"type":"end"}"#, 1), Ok(PageMsg::End));
    assert_eq!(
        parse(r#"{"type":"switch","name":"friction","value":0.5}"#, 1),
        Ok(PageMsg::Switch {
            name: "friction".into(),
            value: 0.5
        })
    );
    assert_eq!(
        parse(
            r#"{"type":"input","seq":7,"pos":[0.6,0,-0.8],"buttons":9,"t_ms":1764000000000.5}"#,
            0b1111
        ),
        Ok(PageMsg::Input(PageInput {
            seq: 7,
            pos: [0.6, 0.0, -0.8],
            buttons: 9,
            t_ms: 1_764_000_000_000.5
        }))
    );
}

#[test]
fn bad_messages_name_the_field_and_range() {
    assert!(err("nope").starts_with("page message is not a JSON object: expected"));
    assert_eq!(
        err("[1]"),
        "page message is not a JSON object: got a list of 1"
    );
    assert_eq!(
        err(r#"{"kind":"input"}"#),
        "page message field `type` is missing (expected: one of start, input, switch, end, answer, step)"
    );
    assert_eq!(
        err(r#"{"type":"jump"}"#),
        "page message `type` = \"jump\" is unknown (allowed: start, input, switch, end, answer, step)"
    );
    let input = |rest: &str| format!(r#"{{"type":"input","seq":1,{rest}}}"#);
    assert_eq!(
        err(&input(r#""pos":[0,0,1.5],"buttons":0,"t_ms":0"#)),
        "page message field `input.pos[2]` = 1.5 is out of range: allowed -1 ≤ value ≤ 1"
    );
    assert_eq!(
        err(&input(r#""pos":[0.8,0.8,0],"buttons":0,"t_ms":0"#)),
        "page message field `input.pos` = [0.8, 0.8, 0] (norm 1.1313708498984762) is out of \
         range: allowed a point of the unit ball, norm ≤ 1"
    );
    assert_eq!(
        err(&input(r#""pos":[0,"a",0],"buttons":0,"t_ms":0"#)),
        "page message field `input.pos[1]` is a string (expected: a number)"
    );
    assert_eq!(
        err(&input(r#""pos":[0,0],"buttons":0,"t_ms":0"#)),
        "page message field `input.pos` is a list of 2 (expected: a list of 3 numbers)"
    );
    assert_eq!(
        err(&input(r#""pos":[0,0,0],"buttons":16,"t_ms":0"#)),
        "page message field `input.buttons` = 16 is out of range: allowed an integer whose \
         bits are the device's buttons, 0–15"
    );
    assert_eq!(
        err(&input(r#""pos":[0,0,0],"buttons":-1,"t_ms":0"#)),
        "page message field `input.buttons` = -1 is out of range: allowed an integer whose \
         bits are the device's buttons, 0–15"
    );
    assert_eq!(
        err(&input(r#""pos":[0,0,0],"buttons":0"#)),
        "page message field `input.t_ms` is missing (expected: a number)"
    );
    assert_eq!(
        err(r#"{"type":"input","seq":-3,"pos":[0,0,0],"buttons":0,"t_ms":0}"#),
        "page message field `input.seq` = -3 is out of range: allowed an integer 0 ≤ seq ≤ \
         9007199254740991"
    );
    assert_eq!(
        err(r#"{"type":"switch","name":"friction","value":"lots"}"#),
        "page message field `switch.value` is a string (expected: a number)"
    );
    assert_eq!(
        err(r#"{"type":"switch","value":1}"#),
        "page message field `switch.name` is missing (expected: a switch name of 1–64 characters)"
    );
    let long = format!(r#"{{"type":"start","pad":"{}"}}"#, "x".repeat(5000));
    assert_eq!(
        err(&long),
        "page message of 5025 bytes is too long (allowed: at most 4096 bytes)"
    );
    // JSON has no NaN or infinity: `1e999` overflows and is refused as not a number.
    assert!(parse(&input(r#""pos":[1e999,0,0],"buttons":0,"t_ms":0"#), 1).is_err());
    assert_eq!(
        ProtocolError::OutOfRange {
            field: "input.pos[2]".into(),
            value: "2".into(),
            allowed: String::new()
        }
        .field(),
        "input.pos[2]"
    );
}

#[test]
fn every_server_message_is_tagged_by_its_type_and_reads_back() {
    let msgs = ServerMsg::examples();
    let names: Vec<&str> = msgs.iter().map(ServerMsg::type_name).collect();
    assert_eq!(names, ServerMsg::TYPES);
    for m in &msgs {
        let text = m.to_json();
        let v: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(v["type"], m.type_name(), "{text}");
        assert!(text.starts_with(&format!(r#"{{"type":"{}""#, m.type_name())));
        let back: ServerMsg = serde_json::from_str(&text).unwrap();
        assert_eq!(&back, m, "{text}");
    }
}

#[test]
fn the_wire_form_of_small_messages() {
    let msgs = ServerMsg::examples();
    assert_eq!(
        msgs[1].to_json(),
        r#"{"type":"waiting","for":"the device's hello"}"#
    );
    assert_eq!(msgs[2].to_json(), r#"{"type":"role","role":"hand"}"#);
    assert_eq!(
        ServerMsg::Role { role: Role::View }.to_json(),
        r#"{"type":"role","role":"view"}"#
    );
    assert_eq!(
        msgs[4].to_json(),
        r#"{"type":"switched","tick":700,"name":"friction","value":0.2}"#
    );
    assert_eq!(
        msgs[5].to_json(),
        r#"{"type":"error","field":"input.pos[2]","message":"out of range"}"#
    );
}

#[test]
fn a_frame_and_the_last_frame_on_the_wire() {
    let msgs = ServerMsg::examples();
    assert_eq!(
        msgs[3].to_json(),
        concat!(
            r#"{"type":"frame","tick":32,"time_s":0.032,"wall_ms":1764000000000.5,"#,
            r#""prims":[{"k":"sphere","c":[0.0,0.0,0.1],"r":0.01,"col":[1.0,0.5,0.0,1.0]}],"#,
            r#""state":{"score":25.0},"cursor_m":[0.0,0.0,0.1],"world_force_n":[0.0,0.0,1.5],"#,
            r#""device_force_n":[0.0,0.0,1.5],"status":1,"#,
            r#""events":[[20,"brick.grabbed","0"]],"sounds":[[21,"thud",0.25]]}"#
        )
    );
    // The session's last frame: no drawing, the last events and sounds.
    let last = ServerMsg::Frame(Frame {
        tick: 1999,
        time_s: 2.0,
        view: None,
        events: Vec::new(),
        sounds: vec![SoundAt(1998, "snap".into(), 1.0)],
    });
    let text = last.to_json();
    assert_eq!(
        text,
        r#"{"type":"frame","tick":1999,"time_s":2.0,"events":[],"sounds":[[1998,"snap",1.0]]}"#
    );
    assert_eq!(serde_json::from_str::<ServerMsg>(&text).unwrap(), last);
    // JSON has no NaN: a non-finite state value is written `null` and reads back as NaN.
    let mut f = match &msgs[3] {
        ServerMsg::Frame(f) => f.clone(),
        _ => unreachable!(),
    };
    if let Some(v) = f.view.as_mut() {
        v.state.insert("nearest_m".into(), f64::NAN);
    }
    let text = ServerMsg::Frame(f).to_json();
    assert!(
        text.contains(r#""state":{"nearest_m":null,"score":25.0}"#),
        "{text}"
    );
    let Ok(ServerMsg::Frame(back)) = serde_json::from_str::<ServerMsg>(&text) else {
        panic!("{text}")
    };
    assert!(back.view.unwrap().state["nearest_m"].is_nan());
}

#[test]
fn an_end_on_the_wire() {
    let msgs = ServerMsg::examples();
    assert_eq!(
        msgs[6].to_json(),
        concat!(
            r#"{"type":"end","end":"stopped","ticks":2000,"seconds":2.0,"missed_deadlines":0,"#,
            r#""tick_work":{"p50_ms":0.01,"p99_ms":0.05,"max_ms":0.2},"state":{"score":25.0},"#,
            r#""peak_device_force_n":2.5,"events":4,"#,
            r#""input_latency_ms":{"n":2,"p50":1.0,"p99":2.0,"max":2.0},"#,
            r#""recording":"/recording.mcap","recording_file":"play.mcap","recording_bytes":4096}"#
        )
    );
    for (e, word) in [
        (EndReason::Completed, "completed"),
        (EndReason::Stopped, "stopped"),
        (EndReason::DeviceEnded, "device_ended"),
    ] {
        assert_eq!(e.name(), word);
        assert_eq!(serde_json::to_value(e).unwrap(), word);
    }
}

#[test]
fn every_page_message_reads_back_through_the_checked_parser() {
    let msgs = PageMsg::examples();
    let names: Vec<&str> = msgs.iter().map(PageMsg::type_name).collect();
    assert_eq!(names, PageMsg::TYPES);
    for m in &msgs {
        let text = m.to_json();
        assert_eq!(parse(&text, 0b1111).as_ref(), Ok(m), "{text}");
    }
    assert_eq!(
        msgs[1].to_json(),
        r#"{"type":"input","seq":7,"pos":[0.6,0.0,-0.8],"buttons":9,"t_ms":1764000000000.5}"#
    );
}

#[test]
fn no_input_panics() {
    // Every prefix of good and bad messages, and odd bytes: errors, never a panic.
    let samples = [
        r#"{"type":"input","seq":7,"pos":[0.6,0,-0.8],"buttons":9,"t_ms":1764000000000.5}"#,
        r#"{"type":"switch","name":"friction","value":0.5}"#,
        "{\"type\":\"\u{0}\"}",
        r#"{"type":"input","seq":1e300,"pos":[null,{},[]],"buttons":1.5,"t_ms":-1}"#,
    ];
    for s in samples {
        for i in 0..=s.len() {
            if s.is_char_boundary(i) {
                let _ = parse(&s[..i], 0b11);
            }
        }
    }
}

#[test]
fn a_lesson_answer_and_step_parse_and_bad_ones_name_their_field() {
    assert_eq!(
        parse(r#"{"type":"answer","choice":1}"#, 0),
        Ok(PageMsg::Answer {
            answer: PageAnswer::Choice(1)
        })
    );
    assert_eq!(
        parse(r#"{"type":"answer","text":"it stuck"}"#, 0),
        Ok(PageMsg::Answer {
            answer: PageAnswer::Text("it stuck".into())
        })
    );
    assert_eq!(
        parse(r#"{"type":"step","id":"snap"}"#, 0),
        Ok(PageMsg::Step { id: "snap".into() })
    );
    assert_eq!(
        err(r#"{"type":"answer","choice":8}"#),
        "page message field `answer.choice` = 8 is out of range: allowed an integer 0 ≤ choice < 8"
    );
    assert_eq!(
        err(r#"{"type":"answer","choice":-1}"#),
        "page message field `answer.choice` = -1 is out of range: allowed an integer 0 ≤ choice < 8"
    );
    assert_eq!(
        err(r#"{"type":"answer","choice":"1"}"#),
        "page message field `answer.choice` is a string (expected: an integer)"
    );
    assert_eq!(
        err(r#"{"type":"answer","text":3}"#),
        "page message field `answer.text` is the number 3 (expected: a string)"
    );
    assert_eq!(
        err(r#"{"type":"answer","choice":1,"text":"a"}"#),
        "page message field `answer` is both choice and text (expected: exactly one of choice (an integer) and text (a string))"
    );
    assert_eq!(
        err(r#"{"type":"answer"}"#),
        "page message field `answer` is missing choice and text (expected: exactly one of choice (an integer) and text (a string))"
    );
    assert_eq!(
        err(r#"{"type":"step","id":""}"#),
        "page message field `step.id` is a string (expected: a step id of 1–64 characters)"
    );
    // A text longer than a message may be is refused whole.
    let long = format!(r#"{{"type":"answer","text":"{}"}}"#, "x".repeat(4100));
    assert_eq!(
        err(&long),
        "page message of 4127 bytes is too long (allowed: at most 4096 bytes)"
    );
}
