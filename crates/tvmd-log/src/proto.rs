//! The protobuf schema of the numeric topics, `tvmd/log.proto` (package `tvmd`).
//!
//! Each message is declared once, in `proto_messages!`: as a prost struct with fixed field
//! numbers (so a log stays readable by every later version) and as its descriptor. Every
//! channel carries the whole file as its MCAP schema (`encoding = "protobuf"`, a serialized
//! `google.protobuf.FileDescriptorSet`), which is how Foxglove and the Python `mcap-protobuf`
//! reader decode it without our code. The SDK's `#[derive(Encode)]` is not used because it
//! names packages after each type and calls its wire format an implementation detail; and
//! this crate reads its own logs back (`tvmd_studies::PlotSeries::from_mcap`) with the same
//! structs.

use std::sync::OnceLock;

use foxglove::bytes::BufMut;
use prost::Message;
use prost_types::field_descriptor_proto::{Label, Type};
use prost_types::{
    DescriptorProto, FieldDescriptorProto, FileDescriptorProto, FileDescriptorSet,
    OneofDescriptorProto,
};

/// The protobuf package of every message.
pub const PACKAGE: &str = "tvmd";
/// The name of the `.proto` file the descriptors describe.
pub const FILE_NAME: &str = "tvmd/log.proto";

/// The fully qualified protobuf name of a message type (`tvmd.State`).
pub trait ProtoName {
    /// `package.Message`.
    const NAME: &'static str;
}

impl<T: ProtoName> ProtoName for Option<T> {
    const NAME: &'static str = T::NAME;
}

impl<T: ProtoName> ProtoName for Vec<T> {
    const NAME: &'static str = T::NAME;
}

/// How a field is declared in the descriptor.
struct FieldSpec {
    name: &'static str,
    number: i32,
    label: Label,
    kind: Type,
    message: Option<&'static str>,
    /// proto3 `optional` (explicit presence, a synthetic one-of).
    optional: bool,
}

fn push_field(d: &mut DescriptorProto, f: FieldSpec) {
    let mut field = FieldDescriptorProto {
        name: Some(f.name.to_string()),
        json_name: Some(f.name.to_string()),
        number: Some(f.number),
        label: Some(f.label as i32),
        r#type: Some(f.kind as i32),
        type_name: f.message.map(|m| format!(".{m}")),
        ..Default::default()
    };
    if f.optional {
        field.oneof_index = Some(d.oneof_decl.len() as i32);
        field.proto3_optional = Some(true);
        d.oneof_decl.push(OneofDescriptorProto {
            name: Some(format!("_{}", f.name)),
            ..Default::default()
        });
    }
    d.field.push(field);
}

/// The descriptor of one field from its prost attribute.
macro_rules! proto_field {
    (@ $name:ident, $num:literal, $label:ident, $kind:ident, $msg:expr, $opt:expr) => {
        FieldSpec {
            name: stringify!($name),
            number: $num,
            label: Label::$label,
            kind: Type::$kind,
            message: $msg,
            optional: $opt,
        }
    };
    ($name:ident, $ty:ty, (double, tag = $n:literal)) => {
        proto_field!(@ $name, $n, Optional, Double, None, false)
    };
    ($name:ident, $ty:ty, (double, optional, tag = $n:literal)) => {
        proto_field!(@ $name, $n, Optional, Double, None, true)
    };
    ($name:ident, $ty:ty, (double, repeated, tag = $n:literal)) => {
        proto_field!(@ $name, $n, Repeated, Double, None, false)
    };
    ($name:ident, $ty:ty, (bool, tag = $n:literal)) => {
        proto_field!(@ $name, $n, Optional, Bool, None, false)
    };
    ($name:ident, $ty:ty, (bool, repeated, tag = $n:literal)) => {
        proto_field!(@ $name, $n, Repeated, Bool, None, false)
    };
    ($name:ident, $ty:ty, (uint32, tag = $n:literal)) => {
        proto_field!(@ $name, $n, Optional, Uint32, None, false)
    };
    ($name:ident, $ty:ty, (uint32, optional, tag = $n:literal)) => {
        proto_field!(@ $name, $n, Optional, Uint32, None, true)
    };
    ($name:ident, $ty:ty, (string, tag = $n:literal)) => {
        proto_field!(@ $name, $n, Optional, String, None, false)
    };
    ($name:ident, $ty:ty, (message, optional, tag = $n:literal)) => {
        proto_field!(@ $name, $n, Optional, Message, Some(<$ty as ProtoName>::NAME), false)
    };
    ($name:ident, $ty:ty, (message, repeated, tag = $n:literal)) => {
        proto_field!(@ $name, $n, Repeated, Message, Some(<$ty as ProtoName>::NAME), false)
    };
}

/// Declares the messages: each a prost struct, its [`ProtoName`], its descriptor and its
/// `foxglove::Encode` implementation; and the list of all descriptors.
macro_rules! proto_messages {
    ($(
        $(#[$meta:meta])*
        $name:ident {
            $( $(#[$fmeta:meta])* $field:ident : $ty:ty => ($($attr:tt)*); )*
        }
    )*) => {
        $(
            $(#[$meta])*
            #[derive(Clone, PartialEq, ::prost::Message)]
            pub struct $name {
                $( $(#[$fmeta])* #[prost($($attr)*)] pub $field: $ty, )*
            }

            impl ProtoName for $name {
                const NAME: &'static str = concat!("tvmd.", stringify!($name));
            }

            impl $name {
                fn descriptor() -> DescriptorProto {
                    let mut d = DescriptorProto {
                        name: Some(stringify!($name).to_string()),
                        ..Default::default()
                    };
                    $( push_field(&mut d, proto_field!($field, $ty, ($($attr)*))); )*
                    d
                }
            }

            impl foxglove::Encode for $name {
                type Error = prost::EncodeError;

                fn get_schema() -> Option<foxglove::Schema> {
                    Some(foxglove::Schema::new(
                        <Self as ProtoName>::NAME,
                        "protobuf",
                        file_descriptor_set(),
                    ))
                }

                fn get_message_encoding() -> String {
                    "protobuf".to_string()
                }

                fn encode(&self, buf: &mut impl BufMut) -> Result<(), Self::Error> {
                    Message::encode(self, buf)
                }

                fn encoded_len(&self) -> Option<usize> {
                    Some(Message::encoded_len(self))
                }
            }
        )*

        fn message_descriptors() -> Vec<DescriptorProto> {
            vec![$($name::descriptor()),*]
        }
    };
}

proto_messages! {
    /// A 3-vector.
    Vec3 {
        /// x.
        x: f64 => (double, tag = 1);
        /// y.
        y: f64 => (double, tag = 2);
        /// z.
        z: f64 => (double, tag = 3);
    }

    /// A unit quaternion `{x, y, z, w}`.
    Quat {
        /// x.
        x: f64 => (double, tag = 1);
        /// y.
        y: f64 => (double, tag = 2);
        /// z.
        z: f64 => (double, tag = 3);
        /// w.
        w: f64 => (double, tag = 4);
    }

    /// One agent's gimbal angles and thrust.
    AgentCommand {
        /// `eta_x` (rad).
        eta_x: f64 => (double, tag = 1);
        /// `eta_y` (rad).
        eta_y: f64 => (double, tag = 2);
        /// Thrust `T_i` (N).
        thrust: f64 => (double, tag = 3);
    }

    /// `/state`: the true state of the team.
    State {
        /// Time (s).
        t: f64 => (double, tag = 1);
        /// `x` (m).
        position: Vec<f64> => (double, repeated, tag = 2);
        /// `x_dot` (m/s).
        velocity: Vec<f64> => (double, repeated, tag = 3);
        /// `v = R^T x_dot` (m/s).
        velocity_body: Vec<f64> => (double, repeated, tag = 4);
        /// Attitude quaternion.
        orientation: Option<Quat> => (message, optional, tag = 5);
        /// Attitude `R`, 9 entries row-major.
        rotation: Vec<f64> => (double, repeated, tag = 6);
        /// Roll, pitch, yaw (ZYX) (rad).
        roll_pitch_yaw: Vec<f64> => (double, repeated, tag = 7);
        /// Body angular velocity `Omega` (rad/s).
        omega: Vec<f64> => (double, repeated, tag = 8);
    }

    /// `/reference`: the reference trajectory.
    Reference {
        /// Time (s).
        t: f64 => (double, tag = 1);
        /// `x_r` (m).
        position: Vec<f64> => (double, repeated, tag = 2);
        /// `x_r_dot` (m/s).
        velocity: Vec<f64> => (double, repeated, tag = 3);
        /// `x_r_ddot` (m/s^2).
        acceleration: Vec<f64> => (double, repeated, tag = 4);
        /// `R_r`, 9 entries row-major.
        rotation: Vec<f64> => (double, repeated, tag = 5);
        /// `Omega_d` (rad/s).
        omega: Vec<f64> => (double, repeated, tag = 6);
        /// `phi_r` (rad).
        roll: f64 => (double, tag = 7);
        /// `phi_r_dot` (rad/s).
        roll_rate: f64 => (double, tag = 8);
        /// Roll, pitch, yaw (ZYX) of `R_r` (rad).
        roll_pitch_yaw: Vec<f64> => (double, repeated, tag = 9);
    }

    /// `/planner`: attitude planner diagnostics.
    Planner {
        /// Time (s).
        t: f64 => (double, tag = 1);
        /// Planned attitude `R_d`, 9 entries row-major.
        r_d: Vec<f64> => (double, repeated, tag = 2);
        /// Roll, pitch, yaw (ZYX) of `R_d` (rad).
        planned_roll_pitch_yaw: Vec<f64> => (double, repeated, tag = 3);
        /// Bisection parameter `theta`.
        theta: f64 => (double, tag = 4);
        /// Projected thrust magnitude `t_tf` (N).
        t_tf: f64 => (double, tag = 5);
        /// `t_eta`.
        t_eta: f64 => (double, tag = 6);
        /// Whether the reference attitude was already feasible.
        reference_feasible: bool => (bool, tag = 7);
        /// Planned roll (rad).
        planned_roll: f64 => (double, tag = 8);
        /// Planner status.
        status: String => (string, tag = 9);
        /// Bisection iterations.
        iterations: u32 => (uint32, tag = 10);
    }

    /// `/control`: control-law diagnostics, or why a cycle was skipped.
    Control {
        /// Time (s).
        t: f64 => (double, tag = 1);
        /// Reference wrench `u_r` (torque, force).
        u_r: Vec<f64> => (double, repeated, tag = 2);
        /// Desired wrench `u_d` (torque, force).
        u_d: Vec<f64> => (double, repeated, tag = 3);
        /// Position error `e_x` (m).
        e_x: Vec<f64> => (double, repeated, tag = 4);
        /// Velocity error `e_v` (m/s).
        e_v: Vec<f64> => (double, repeated, tag = 5);
        /// Attitude error `e_R`.
        e_r: Vec<f64> => (double, repeated, tag = 6);
        /// Angular velocity error `e_Omega` (rad/s).
        e_omega: Vec<f64> => (double, repeated, tag = 7);
        /// `t_tf` (N).
        t_tf: f64 => (double, tag = 8);
        /// `t_eta`.
        t_eta: f64 => (double, tag = 9);
        /// Controller-specific extras as JSON text (empty if none).
        extra_json: String => (string, tag = 10);
        /// Why the cycle was skipped (empty if it ran).
        cycle_error: String => (string, tag = 11);
        /// The controller's note on failures (empty if none).
        failure_note: String => (string, tag = 12);
    }

    /// Null-space redistribution diagnostics.
    NullSpace {
        /// Iterations.
        iterations: u32 => (uint32, tag = 1);
        /// Objective before and after.
        objective: Vec<f64> => (double, repeated, tag = 2);
        /// Margin before and after.
        margin: Vec<f64> => (double, repeated, tag = 3);
        /// Largest change of an agent force (N).
        largest_force_change: f64 => (double, tag = 4);
        /// Drift of the wrench (N).
        wrench_drift: f64 => (double, tag = 5);
    }

    /// `/allocation`: allocation diagnostics.
    Allocation {
        /// Time (s).
        t: f64 => (double, tag = 1);
        /// Allocated wrench (torque, force).
        wrench: Vec<f64> => (double, repeated, tag = 2);
        /// Force error `e_f` (N).
        e_f: f64 => (double, tag = 3);
        /// Agents at a limit.
        saturated: Vec<bool> => (bool, repeated, tag = 4);
        /// Wrench error.
        wrench_error: f64 => (double, tag = 5);
        /// Redistribution rounds.
        rounds: u32 => (uint32, tag = 6);
        /// Whether the fallback allocator ran.
        fallback: bool => (bool, tag = 7);
        /// Agent forces (N).
        forces: Vec<Vec3> => (message, repeated, tag = 8);
        /// Rotor speeds (rad/s).
        rotor_speeds: Vec<f64> => (double, repeated, tag = 9);
        /// Null-space diagnostics, if that allocator ran.
        null_space: Option<NullSpace> => (message, optional, tag = 10);
    }

    /// `/actuators`: commanded and actual agent commands, failures.
    Actuators {
        /// Time (s).
        t: f64 => (double, tag = 1);
        /// Commands from the controller (held).
        commanded: Vec<AgentCommand> => (message, repeated, tag = 2);
        /// Actual actuator outputs.
        actual: Vec<AgentCommand> => (message, repeated, tag = 3);
        /// True failure flags.
        failed: Vec<bool> => (bool, repeated, tag = 4);
        /// Actual agent forces in the body frame (N).
        forces_body: Vec<Vec3> => (message, repeated, tag = 5);
    }

    /// `/lyapunov`: the Lyapunov candidates.
    Lyapunov {
        /// Time (s).
        t: f64 => (double, tag = 1);
        /// `V_x`.
        v_x: f64 => (double, tag = 2);
        /// `V_R`.
        v_r: f64 => (double, tag = 3);
    }

    /// `/hover`: the hover classification, when the failure mask changes.
    Hover {
        /// Time (s).
        t: f64 => (double, tag = 1);
        /// Whether the team can hover.
        capable: bool => (bool, tag = 2);
        /// Hover margin.
        margin: f64 => (double, tag = 3);
        /// The agent that limits hover, if any.
        limiting_agent: Option<u32> => (uint32, optional, tag = 4);
        /// What limits it.
        limit: String => (string, tag = 5);
        /// Whether the controller lands.
        landing: bool => (bool, tag = 6);
    }

    /// `/fault`: the fault detector's report, every period it runs.
    Fault {
        /// Time (s).
        t: f64 => (double, tag = 1);
        /// The residual in noise units.
        statistic: f64 => (double, tag = 2);
        /// The threshold it is compared with.
        threshold: f64 => (double, tag = 3);
        /// `nominal`, `unexplained`, `suspected` or `confirmed`.
        verdict: String => (string, tag = 4);
        /// The isolated agent, if any.
        agent: Option<u32> => (uint32, optional, tag = 5);
        /// `loss`, `partial-loss`, `stuck-gimbal`, `link-loss`, or empty.
        kind: String => (string, tag = 6);
        /// The fraction delivered, for a partial loss.
        efficiency: Option<f64> => (double, optional, tag = 7);
        /// The agent the controller masked itself this period, if any.
        masked: Option<u32> => (uint32, optional, tag = 8);
        /// Consecutive periods the agent has been the candidate (suspected).
        periods: u32 => (uint32, tag = 9);
        /// The check that named the agent: `residual`, `reports`, or empty.
        source: String => (string, tag = 10);
    }
}

/// The serialized `FileDescriptorSet` of `tvmd/log.proto` (built once).
pub fn file_descriptor_set() -> &'static [u8] {
    static SET: OnceLock<Vec<u8>> = OnceLock::new();
    SET.get_or_init(|| {
        let file = FileDescriptorProto {
            name: Some(FILE_NAME.to_string()),
            package: Some(PACKAGE.to_string()),
            message_type: message_descriptors(),
            syntax: Some("proto3".to_string()),
            ..Default::default()
        };
        FileDescriptorSet { file: vec![file] }.encode_to_vec()
    })
}

impl Vec3 {
    /// From a nalgebra vector.
    pub fn of(v: &nalgebra::Vector3<f64>) -> Self {
        Self {
            x: v.x,
            y: v.y,
            z: v.z,
        }
    }
}

#[cfg(test)]
#[path = "proto_tests.rs"]
mod tests;
