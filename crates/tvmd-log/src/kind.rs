//! The message kinds of a log, one channel each.

use crate::proto;

/// The message kinds of a simulation log (one channel each).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum LogKind {
    /// True state ([`proto::State`]).
    State,
    /// Reference ([`proto::Reference`]).
    Reference,
    /// Planner diagnostics ([`proto::Planner`]).
    Planner,
    /// Control-law diagnostics ([`proto::Control`]).
    Control,
    /// Allocation diagnostics ([`proto::Allocation`]).
    Allocation,
    /// Actuators ([`proto::Actuators`]).
    Actuators,
    /// Lyapunov candidates ([`proto::Lyapunov`]).
    Lyapunov,
    /// Hover classification ([`proto::Hover`]).
    Hover,
    /// Fault detector report ([`proto::Fault`]).
    Fault,
    /// The team's pose (`foxglove.FrameTransform`).
    FrameTransform,
    /// The 3D scene (`foxglove.SceneUpdate`).
    Scene,
}

impl LogKind {
    /// All kinds, in channel order.
    pub const ALL: [LogKind; 11] = [
        LogKind::State,
        LogKind::Reference,
        LogKind::Planner,
        LogKind::Control,
        LogKind::Allocation,
        LogKind::Actuators,
        LogKind::Lyapunov,
        LogKind::Hover,
        LogKind::Fault,
        LogKind::FrameTransform,
        LogKind::Scene,
    ];

    /// The channel's topic.
    pub fn topic(self) -> &'static str {
        match self {
            Self::State => "/state",
            Self::Reference => "/reference",
            Self::Planner => "/planner",
            Self::Control => "/control",
            Self::Allocation => "/allocation",
            Self::Actuators => "/actuators",
            Self::Lyapunov => "/lyapunov",
            Self::Hover => "/hover",
            Self::Fault => "/fault",
            Self::FrameTransform => "/tf",
            Self::Scene => "/scene",
        }
    }

    /// The protobuf message name of the channel's schema.
    pub fn schema_name(self) -> &'static str {
        use proto::ProtoName;
        match self {
            Self::State => proto::State::NAME,
            Self::Reference => proto::Reference::NAME,
            Self::Planner => proto::Planner::NAME,
            Self::Control => proto::Control::NAME,
            Self::Allocation => proto::Allocation::NAME,
            Self::Actuators => proto::Actuators::NAME,
            Self::Lyapunov => proto::Lyapunov::NAME,
            Self::Hover => proto::Hover::NAME,
            Self::Fault => proto::Fault::NAME,
            Self::FrameTransform => "foxglove.FrameTransform",
            Self::Scene => "foxglove.SceneUpdate",
        }
    }

    /// True for the topics the scenario's `[log] decimation` thins.
    pub fn is_heavy(self) -> bool {
        matches!(
            self,
            Self::Planner | Self::Control | Self::Allocation | Self::Actuators
        )
    }
}
