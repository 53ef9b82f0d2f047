//! Decoding a datagram: the header checked, then one decoder per packet type; every malformed
//! input is an error, never a panic.

use super::reader::Reader;
use super::{
    BYE_LEN, FORCE_LEN, HEADER_LEN, LOCAL_FIXED_LEN, MAGIC, MAX_PACKET, SAMPLE_LEN, SAMPLE_V2_LEN,
    VERSION, VERSION_2, VERSION_3, VERSION_4,
};
use super::{ForceReply, Packet, ProtocolError, Refusal, Sample};
use haptic_types::device::DeviceSpecs;
use std::borrow::Cow;

impl Packet {
    /// Decodes a datagram; every malformed input is an error, never a panic.
    pub fn decode(b: &[u8]) -> Result<Packet, ProtocolError> {
        if b.len() > MAX_PACKET {
            return Err(ProtocolError::Oversized(b.len()));
        }
        if b.len() < HEADER_LEN {
            return Err(ProtocolError::TooShort {
                kind: "header",
                got: b.len(),
                need: HEADER_LEN,
            });
        }
        let magic = [b[0], b[1], b[2], b[3]];
        if magic != MAGIC {
            return Err(ProtocolError::Magic(magic));
        }
        let version = b[4];
        let mut r = Reader::new(b, HEADER_LEN);
        if b[5] == 1 {
            // A hello of any version above 0 is read (its body is the same in every version)
            // and welcomed with the smaller of its version and 4; one that cannot be accepted
            // is answered with a refusal naming the field.
            return hello(version, &mut r).map_err(refusal);
        }
        if !(VERSION..=VERSION_4).contains(&version) {
            return Err(ProtocolError::Version(version));
        }
        match b[5] {
            2 => welcome(version, &mut r),
            3 => sample(version, b, &mut r),
            4 => force(version, b, &mut r),
            5 => bye(b, &mut r),
            super::REFUSAL_TYPE => refused(&mut r),
            t => Err(ProtocolError::Type(t)),
        }
    }
}

/// A packet of a fixed size: `b` must be exactly `len` bytes long (`kind` names it).
fn fixed(b: &[u8], kind: &'static str, len: usize) -> Result<(), ProtocolError> {
    if b.len() < len {
        Err(ProtocolError::TooShort {
            kind,
            got: b.len(),
            need: len,
        })
    } else if b.len() > len {
        Err(ProtocolError::TooLong {
            kind,
            got: b.len(),
            expected: len,
        })
    } else {
        Ok(())
    }
}

/// A hello's error as a refusal naming the field and the allowed values.
fn refusal(e: ProtocolError) -> ProtocolError {
    let layout = "36 bytes of header, rate and limits, then the name and each button as a u8 \
                  length and 1–32 printable ASCII characters";
    match e {
        ProtocolError::Hello(_) => e,
        ProtocolError::Text(kind) => {
            let field = if kind == "hello name" {
                "name"
            } else {
                "button_names"
            };
            ProtocolError::Hello(Refusal::new(
                field,
                "1–32 printable ASCII characters",
                format!("hello refused: `{field}` is not text"),
            ))
        }
        other => ProtocolError::Hello(Refusal::new(
            "size",
            layout,
            format!("hello refused: {other}"),
        )),
    }
}

/// Type 1, a hello: the device's specifications, checked.
fn hello(version: u8, r: &mut Reader) -> Result<Packet, ProtocolError> {
    if version == 0 {
        return Err(ProtocolError::Hello(Refusal::new(
            "version",
            "1 or more (a hello above 4 is welcomed with version 4)",
            "hello refused: `version` = 0 is out of range: allowed 1 or more (a hello above 4 \
             is welcomed with version 4)"
                .into(),
        )));
    }
    let rate_hz = r.u32("hello")?;
    let max_force_n = r.f64("hello")?;
    let max_stiffness_n_per_m = r.f64("hello")?;
    let workspace_radius_m = r.f64("hello")?;
    let name = r.string("hello name")?;
    let n = r.u8("hello")?;
    let mut buttons = Vec::with_capacity(usize::from(n));
    for _ in 0..n {
        buttons.push(Cow::Owned(r.string("hello button name")?));
    }
    r.end("hello")?;
    let specs = DeviceSpecs {
        name: Cow::Owned(name),
        limits: world_form::Limits {
            max_force_n,
            max_stiffness_n_per_m,
        },
        workspace_radius_m,
        button_names: Cow::Owned(buttons),
    };
    specs
        .validate()
        .map_err(|e| ProtocolError::Hello(Refusal::of_spec(&e)))?;
    Ok(Packet::Hello {
        version,
        rate_hz,
        specs,
    })
}

/// Type 2, a welcome.
fn welcome(version: u8, r: &mut Reader) -> Result<Packet, ProtocolError> {
    let rate_hz = r.u32("welcome")?;
    let start_time_ns = r.u64("welcome")?;
    let scene = r.string("welcome scene")?;
    // The button roles (issue 41); a welcome from an older simulator ends at the scene name.
    let roles = if r.remaining() == 0 {
        None
    } else {
        Some([
            r.u8("welcome")?,
            r.u8("welcome")?,
            r.u8("welcome")?,
            r.u8("welcome")?,
        ])
    };
    r.end("welcome")?;
    Ok(Packet::Welcome {
        version,
        rate_hz,
        start_time_ns,
        scene,
        roles,
    })
}

/// Type 6, a refusal: the field, the allowed values and the message.
fn refused(r: &mut Reader) -> Result<Packet, ProtocolError> {
    let field = r.string("refusal field")?;
    let allowed = r.string("refusal allowed")?;
    let message = r.string("refusal message")?;
    r.end("refusal")?;
    Ok(Packet::Refusal(Refusal {
        field,
        allowed,
        message,
    }))
}

/// Type 3, a sample of the size its version gives (`b`: the whole datagram; a version-3
/// sample is a version-2 sample).
fn sample(version: u8, b: &[u8], r: &mut Reader) -> Result<Packet, ProtocolError> {
    if version == VERSION {
        fixed(b, "sample", SAMPLE_LEN)?;
    } else {
        fixed(b, "sample (version 2)", SAMPLE_V2_LEN)?;
    }
    Ok(Packet::Sample(Sample {
        seq: r.u64("sample")?,
        device_time_ns: r.u64("sample")?,
        position_m: [r.f64("sample")?, r.f64("sample")?, r.f64("sample")?],
        buttons: r.u32("sample")?,
        two_port_periods: if version >= VERSION_2 {
            Some(r.u32("sample")?)
        } else {
            None
        },
    }))
}

/// Type 4, a force: the version-1 fields, then in version 2 the local model, in version 3 the
/// local model and its bond, and in version 4 the local model, a bond flag, the bond if the
/// flag is 1, and the follower (`b`: the whole datagram).
fn force(version: u8, b: &[u8], r: &mut Reader) -> Result<Packet, ProtocolError> {
    if version == VERSION {
        fixed(b, "force", FORCE_LEN)?;
    } else if b.len() < FORCE_LEN + LOCAL_FIXED_LEN + 3 {
        return Err(ProtocolError::TooShort {
            kind: "force (version 2)",
            got: b.len(),
            need: FORCE_LEN + LOCAL_FIXED_LEN + 3,
        });
    }
    let seq = r.u64("force")?;
    let tick = r.u64("force")?;
    let force_n = [r.f64("force")?, r.f64("force")?, r.f64("force")?];
    let mut k = [0.0; 9];
    for x in &mut k {
        *x = r.f64("force")?;
    }
    let status = r.u8("force")?;
    let local = match version {
        VERSION_2 => {
            let m = r.local()?;
            r.end("force (version 2)")?;
            Some(Box::new(m))
        }
        VERSION_3 => {
            let mut m = r.local()?;
            m.bond = Some(r.bond("force (version 3)")?);
            m.check(f64::INFINITY).map_err(ProtocolError::Local)?;
            r.end("force (version 3)")?;
            Some(Box::new(m))
        }
        VERSION_4 => {
            let mut m = r.local()?;
            m.bond = match r.u8("force (version 4)")? {
                0 => None,
                1 => Some(r.bond("force (version 4)")?),
                other => {
                    return Err(ProtocolError::Local(format!(
                        "bond flag {other}: allowed 0 (none) or 1"
                    )));
                }
            };
            m.follower = Some(r.follower()?);
            m.check(f64::INFINITY).map_err(ProtocolError::Local)?;
            r.end("force (version 4)")?;
            Some(Box::new(m))
        }
        _ => None,
    };
    Ok(Packet::Force(ForceReply {
        seq,
        tick,
        force_n,
        stiffness_n_per_m: k,
        status,
        local,
    }))
}

/// Type 5, a bye (`b`: the whole datagram).
fn bye(b: &[u8], r: &mut Reader) -> Result<Packet, ProtocolError> {
    fixed(b, "bye", BYE_LEN)?;
    Ok(Packet::Bye {
        reason: r.u8("bye")?,
    })
}
