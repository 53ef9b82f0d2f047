//! The declaration form of the recording's channels: one `recording_channels!` invocation (in
//! [`super::messages`]) lists every channel once, and each CDR channel's message once as a list
//! of fields (type, name, doc with the unit, optional `.msg` comment lines, optional per-tick
//! column, and where its value comes from in a tick). From that list the macro builds:
//!
//! - the [`Channel`](super::messages::Channel) enum (topics, rates, what replay does with it);
//! - each message's struct with doc comments, its CDR encoder and decoder
//!   ([`super::cdr::CdrField`]), its ROS 2 `.msg` schema text (comments included) and its
//!   [`FieldInfo`] list;
//! - its constructor from a tick (`from_tick`), used alike by the recorder and the per-tick
//!   arrays;
//! - [`TickColumns`](super::messages::TickColumns), the per-tick columns (struct of arrays) of
//!   every field that names a column, with their names and descriptions for Python
//!   ([`ColumnInfo`], [`ColumnData`]);
//! - the documentation tables of `docs/recording-format.md` ([`super::doc`]).

use super::cdr::CdrField;
use haptic_types::vec3::Vec3;

/// One field of a declared message.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FieldInfo {
    /// Field name (the `.msg` name and the Rust field name).
    pub name: &'static str,
    /// Its `.msg` type (`uint64`, `float64[3]`, …).
    pub msg_type: &'static str,
    /// Its doc comment, with the unit (one line per doc line, each starting with a space).
    pub doc: &'static str,
    /// The comment lines written before the field in the `.msg` schema text (without `# `).
    pub msg_comments: &'static [&'static str],
    /// The per-tick column it fills, if any.
    pub column: Option<&'static str>,
    /// One `float64` per scene state field, appended by the scene (not part of the fixed text).
    pub per_scene: bool,
}

impl FieldInfo {
    /// The doc comment on one line (doc lines joined by spaces).
    pub fn doc_line(&self) -> String {
        let parts: Vec<&str> = self
            .doc
            .lines()
            .map(str::trim)
            .filter(|l| !l.is_empty())
            .collect();
        parts.join(" ")
    }
}

/// What replay does with a channel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// An input of replay (played back, not recomputed).
    Input,
    /// Recomputed by replay and compared bit for bit.
    Verified,
    /// Neither (wall-clock measurements).
    Unverified,
}

impl Role {
    /// The words used in the documentation's channel table.
    pub fn words(self) -> &'static str {
        match self {
            Role::Input => "input",
            Role::Verified => "verified",
            Role::Unverified => "not compared (wall clock)",
        }
    }
}

/// A declared CDR message (one per CDR channel).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MessageInfo {
    /// Rust type name.
    pub rust_name: &'static str,
    /// Schema name (`nanohaptics_msgs/msg/Force`; `<Kind>` for the per-scene state).
    pub schema_name: &'static str,
    /// The schema's first comment line (without `# `).
    pub comment: &'static str,
    /// The fields, in wire order.
    pub fields: &'static [FieldInfo],
}

/// Name and description of one per-tick column.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ColumnInfo {
    /// Column name (the field of `SessionArrays`, the key in Python).
    pub name: &'static str,
    /// The field's doc comment, with the unit.
    pub doc: &'static str,
}

/// A column's values, by element type (for conversion to numpy and other tables).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ColumnData<'a> {
    /// `uint8` per tick.
    U8(&'a [u8]),
    /// `bool` per tick.
    Bool(&'a [bool]),
    /// `uint32` per tick.
    U32(&'a [u32]),
    /// `uint64` per tick.
    U64(&'a [u64]),
    /// `int64` per tick.
    I64(&'a [i64]),
    /// `float64` per tick.
    F64(&'a [f64]),
    /// `float64[3]` per tick.
    Vec3(&'a [Vec3]),
    /// `float64[9]` (row-major 3×3) per tick.
    Mat3(&'a [[f64; 9]]),
    /// The scene's state fields, ticks × fields, row-major.
    Table(&'a [f64]),
}

/// A field type that can be a per-tick column.
pub trait ColumnField: CdrField {
    /// The column's storage.
    type Column: Clone + std::fmt::Debug + Default + PartialEq + serde::Serialize;
    /// Appends the field's value to the column.
    fn push_to(&self, col: &mut Self::Column);
    /// Reserves room for `rows` more ticks of `width` scene fields.
    fn reserve(col: &mut Self::Column, rows: usize, width: usize);
    /// The column's values.
    fn data(col: &Self::Column) -> ColumnData<'_>;
}

macro_rules! column_of {
    ($($t:ty => $v:ident;)*) => {$(
        impl ColumnField for $t {
            type Column = Vec<$t>;
            fn push_to(&self, col: &mut Vec<$t>) {
                col.push(*self);
            }
            fn reserve(col: &mut Vec<$t>, rows: usize, _width: usize) {
                col.reserve(rows);
            }
            fn data(col: &Vec<$t>) -> ColumnData<'_> {
                ColumnData::$v(col)
            }
        }
    )*};
}

column_of! {
    u8 => U8;
    bool => Bool;
    u32 => U32;
    u64 => U64;
    i64 => I64;
    f64 => F64;
    [f64; 3] => Vec3;
    [f64; 9] => Mat3;
}

/// Declares the recording's channels and messages; see the module documentation. The syntax,
/// one entry per channel in registration order (which is the order of the schemas and channels
/// in every file):
///
/// ```text
/// channel Force = "/haptic/force", verified, "every tick",
///     message ForceMsg(Clone, Copy, Debug, PartialEq) = "nanohaptics_msgs/msg/Force",
///     "first comment line of the schema",
///     from(r: &TickResult)                     // parameters of `ForceMsg::from_tick`
/// {
///     /// Doc comment, with the unit.
///     #[msg = "a comment line written before the field in the schema"]
///     field_name: f64 => column_name = r.source_expression,
/// }
/// protobuf FoxgloveTf = "/foxglove/tf", verified, "display rate", "foxglove.FrameTransform";
/// ```
///
/// `decode = custom` leaves `decode` to a hand-written function (the state's, which checks
/// the number of scene fields); `decode_message` is always generated.
/// `=> column` (optional) makes the field a per-tick column; `= expr` gives its value in
/// `from_tick` (every field of a message with `from(…)` needs one). `#[check = path]` runs
/// `path(&value)?` right after the field is decoded; `validate = path` after the message is.
macro_rules! recording_channels {
    (
        $(
            channel $ch:ident = $topic:literal, $role:ident, $rate:literal,
            message $msg:ident ($($derive:path),* $(,)?) = $schema:literal, $head:literal
            $(, from ($($p:ident : $pt:ty),* $(,)?))?
            $(, validate = $validate:path)?
            $(, decode = $decode:ident)?
            {
                $(
                    $(#[doc = $fdoc:literal])*
                    $(#[msg = $fmsg:literal])*
                    $(#[check = $fcheck:path])?
                    $fname:ident : $fty:ty $(=> $col:ident)? $(= $src:expr)?
                ),* $(,)?
            }
        )*
        $(
            protobuf $pch:ident = $ptopic:literal, $prole:ident, $prate:literal, $pschema:literal;
        )*
    ) => {
        /// The channels of a recording, in registration order.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum Channel {
            $(
                #[doc = concat!("`", $topic, "` (`", $schema, "`), ", $rate, ".")]
                $ch,
            )*
            $(
                #[doc = concat!("`", $ptopic, "` (`", $pschema, "`), ", $prate, ".")]
                $pch,
            )*
        }

        impl Channel {
            /// Number of channels.
            pub const COUNT: usize = [$(stringify!($ch),)* $(stringify!($pch),)*].len();

            /// Every channel, in registration order.
            pub const ALL: [Channel; Channel::COUNT] = [$(Channel::$ch,)* $(Channel::$pch,)*];

            /// MCAP topic.
            pub fn topic(self) -> &'static str {
                match self {
                    $(Channel::$ch => $topic,)*
                    $(Channel::$pch => $ptopic,)*
                }
            }

            /// When the channel has a message (`every tick`, `ticks with events`, …).
            pub fn rate(self) -> &'static str {
                match self {
                    $(Channel::$ch => $rate,)*
                    $(Channel::$pch => $prate,)*
                }
            }

            /// What replay does with the channel.
            pub fn role(self) -> $crate::channels::declare::Role {
                match self {
                    $(Channel::$ch => $crate::channels::declare::Role::$role,)*
                    $(Channel::$pch => $crate::channels::declare::Role::$prole,)*
                }
            }

            /// Schema name (for the per-scene state, `<Kind>` stands for the scene kind).
            pub fn schema_name(self) -> &'static str {
                match self {
                    $(Channel::$ch => $schema,)*
                    $(Channel::$pch => $pschema,)*
                }
            }

            /// Message encoding: `cdr` for the declared messages, `protobuf` for Foxglove's.
            pub fn message_encoding(self) -> &'static str {
                match self {
                    $(Channel::$ch => "cdr",)*
                    $(Channel::$pch => "protobuf",)*
                }
            }

            /// The declared message of a CDR channel.
            pub fn message(self) -> Option<&'static $crate::channels::declare::MessageInfo> {
                match self {
                    $(Channel::$ch => Some(&$msg::INFO),)*
                    $(Channel::$pch => None,)*
                }
            }

            /// The schema name and `.msg` text of a CDR channel (for the per-scene state, the
            /// fixed part only: see `state_schema`).
            pub fn ros2_schema(self) -> Option<(&'static str, String)> {
                match self {
                    $(Channel::$ch => Some(($schema, $msg::schema_text())),)*
                    $(Channel::$pch => None,)*
                }
            }

            /// Decodes `data` of this channel and appends its fields that are columns to `c`
            /// (nothing for channels without columns; their messages are not decoded).
            pub fn push_columns(
                self,
                data: &[u8],
                c: &mut TickColumns,
            ) -> Result<(), $crate::channels::cdr::CdrError> {
                match self {
                    $(Channel::$ch => {
                        if $msg::INFO.fields.iter().any(|f| f.column.is_some()) {
                            $msg::decode_message(data)?.push_columns(c);
                        }
                    })*
                    $(Channel::$pch => {})*
                }
                Ok(())
            }
        }

        /// Every declared CDR message, in channel order.
        pub const MESSAGES: &[&$crate::channels::declare::MessageInfo] = &[$(&$msg::INFO),*];

        $(
            #[doc = concat!("`", $topic, "`: ", $head)]
            #[derive($($derive),*)]
            pub struct $msg {
                $(
                    $(#[doc = $fdoc])*
                    pub $fname: $fty,
                )*
            }

            impl $msg {
                /// The declaration: schema name, comment and fields.
                pub const INFO: $crate::channels::declare::MessageInfo =
                    $crate::channels::declare::MessageInfo {
                        rust_name: stringify!($msg),
                        schema_name: $schema,
                        comment: $head,
                        fields: &[$(
                            $crate::channels::declare::FieldInfo {
                                name: stringify!($fname),
                                msg_type: <$fty as $crate::channels::cdr::CdrField>::MSG_TYPE,
                                doc: concat!($($fdoc, "\n",)*),
                                msg_comments: &[$($fmsg),*],
                                column: recording_channels!(@opt [$(stringify!($col))?]),
                                per_scene: <$fty as $crate::channels::cdr::CdrField>::MSG_TYPE
                                    .is_empty(),
                            },
                        )*],
                    };

                /// The ROS 2 `.msg` schema text (comments included).
                pub fn schema_text() -> String {
                    $crate::channels::declare::schema_text(&Self::INFO)
                }

                /// Encodes to CDR.
                pub fn encode(&self) -> Vec<u8> {
                    let mut w = $crate::channels::cdr::CdrWriter::new();
                    $($crate::channels::cdr::CdrField::put(&self.$fname, &mut w);)*
                    w.finish()
                }

                /// Decodes from CDR (the whole message, no byte left).
                pub fn decode_message(b: &[u8]) -> Result<Self, $crate::channels::cdr::CdrError> {
                    let mut r = $crate::channels::cdr::CdrReader::new(b)?;
                    $(
                        let $fname = <$fty as $crate::channels::cdr::CdrField>::get(&mut r)?;
                        $($fcheck(&$fname)?;)?
                    )*
                    r.end()?;
                    let m = $msg { $($fname),* };
                    $($validate(&m)?;)?
                    Ok(m)
                }

                /// Appends the fields that are per-tick columns to `c`.
                #[allow(unused_variables)]
                pub fn push_columns(&self, c: &mut TickColumns) {
                    $(recording_channels!(@push self c $fname [$($col)?]);)*
                }
            }

            recording_channels!(@from $msg [$(($($p : $pt),*))?] [$($fname [$($src)?]),*]);
            recording_channels!(@decode $msg [$($decode)?]);
        )*

        recording_channels!(@columns [] $($([$($col)?] [$($fdoc)*] $fty;)*)*);
    };

    (@decode $msg:ident []) => {
        impl $msg {
            /// Decodes from CDR (the whole message, no byte left).
            pub fn decode(b: &[u8]) -> Result<Self, $crate::channels::cdr::CdrError> {
                Self::decode_message(b)
            }
        }
    };
    (@decode $msg:ident [custom]) => {};

    (@opt []) => { None };
    (@opt [$e:expr]) => { Some($e) };

    (@push $s:ident $c:ident $f:ident []) => {};
    (@push $s:ident $c:ident $f:ident [$col:ident]) => {
        $crate::channels::declare::ColumnField::push_to(&$s.$f, &mut $c.$col)
    };

    (@from $msg:ident [] [$($rest:tt)*]) => {};
    (@from $msg:ident [($($p:ident : $pt:ty),*)] [$($f:ident [$($s:expr)?]),*]) => {
        impl $msg {
            /// The message of a tick, built straight from the tick (no encoding).
            pub fn from_tick($($p: $pt),*) -> Self {
                $msg { $($f: recording_channels!(@src $f [$($s)?])),* }
            }
        }
    };
    (@src $f:ident []) => {
        compile_error!(concat!("field `", stringify!($f), "` has no `= source` in a message with `from(…)`"))
    };
    (@src $f:ident [$s:expr]) => { $s };

    (@columns [$(($c:ident [$($d:literal)*] $t:ty))*]) => {
        /// The per-tick columns of every declared field that names one (struct of arrays; the
        /// scene state is row-major ticks × fields).
        #[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
        pub struct TickColumns {
            $(
                $(#[doc = $d])*
                pub $c: <$t as $crate::channels::declare::ColumnField>::Column,
            )*
        }

        impl TickColumns {
            /// Name and description of every column, in declaration order.
            pub const INFO: &[$crate::channels::declare::ColumnInfo] = &[$(
                $crate::channels::declare::ColumnInfo {
                    name: stringify!($c),
                    doc: concat!($($d, "\n",)*),
                },
            )*];

            /// Reserves room for `ticks` more ticks of a scene with `width` state fields.
            pub fn reserve(&mut self, ticks: usize, width: usize) {
                $(<$t as $crate::channels::declare::ColumnField>::reserve(
                    &mut self.$c,
                    ticks,
                    width,
                );)*
            }

            /// Every column with its values, in the order of [`TickColumns::INFO`].
            pub fn columns(
                &self,
            ) -> Vec<(
                &'static $crate::channels::declare::ColumnInfo,
                $crate::channels::declare::ColumnData<'_>,
            )> {
                let data = [$(
                    <$t as $crate::channels::declare::ColumnField>::data(&self.$c),
                )*];
                Self::INFO.iter().zip(data).collect()
            }
        }
    };
    (@columns [$($acc:tt)*] [] [$($d:literal)*] $t:ty; $($rest:tt)*) => {
        recording_channels!(@columns [$($acc)*] $($rest)*);
    };
    (@columns [$($acc:tt)*] [$c:ident] [$($d:literal)*] $t:ty; $($rest:tt)*) => {
        recording_channels!(@columns [$($acc)* ($c [$($d)*] $t)] $($rest)*);
    };
}

pub(crate) use recording_channels;

/// The `.msg` schema text of a declared message: its comment line, then each field's comment
/// lines and `type name` line (per-scene fields are appended by the scene, not here).
pub fn schema_text(m: &MessageInfo) -> String {
    let mut s = format!("# {}\n", m.comment);
    for f in m.fields.iter().filter(|f| !f.per_scene) {
        for c in f.msg_comments {
            s.push_str("# ");
            s.push_str(c);
            s.push('\n');
        }
        s.push_str(f.msg_type);
        s.push(' ');
        s.push_str(f.name);
        s.push('\n');
    }
    s
}
