//! The log's channels, one per topic, and the messages that go on them.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use foxglove::messages::{FrameTransform, SceneUpdate};
use foxglove::{Channel, Context, Encode};

use crate::{nanos, proto, LogKind};

/// The count of messages written, shared by the writer thread and its log.
pub(crate) type Written = Arc<AtomicU64>;

/// One typed channel per topic, all in the log's context.
pub(crate) struct Channels {
    state: Channel<proto::State>,
    reference: Channel<proto::Reference>,
    planner: Channel<proto::Planner>,
    control: Channel<proto::Control>,
    allocation: Channel<proto::Allocation>,
    actuators: Channel<proto::Actuators>,
    lyapunov: Channel<proto::Lyapunov>,
    hover: Channel<proto::Hover>,
    fault: Channel<proto::Fault>,
    tf: Channel<FrameTransform>,
    scene: Channel<SceneUpdate>,
}

impl Channels {
    pub(crate) fn new(ctx: &Arc<Context>) -> Self {
        fn build<T: Encode>(ctx: &Arc<Context>, kind: LogKind) -> Channel<T> {
            ctx.channel_builder(kind.topic()).build()
        }
        Self {
            state: build(ctx, LogKind::State),
            reference: build(ctx, LogKind::Reference),
            planner: build(ctx, LogKind::Planner),
            control: build(ctx, LogKind::Control),
            allocation: build(ctx, LogKind::Allocation),
            actuators: build(ctx, LogKind::Actuators),
            lyapunov: build(ctx, LogKind::Lyapunov),
            hover: build(ctx, LogKind::Hover),
            fault: build(ctx, LogKind::Fault),
            tf: build(ctx, LogKind::FrameTransform),
            scene: build(ctx, LogKind::Scene),
        }
    }
}

/// A message the log can write: which channel it goes to.
pub trait LogMessage: Encode + Send + Sized + 'static {
    /// Its kind.
    const KIND: LogKind;
    #[doc(hidden)]
    fn log(&self, channels: &LogChannels, nanos: u64);
}

/// The channels of a [`crate::RunLog`], owned by its writer thread: a [`crate::writer::LogJob`] writes through them.
pub struct LogChannels {
    pub(crate) channels: Channels,
    pub(crate) written: Written,
}

macro_rules! log_message {
    ($ty:ty, $kind:ident, $field:ident) => {
        impl LogMessage for $ty {
            const KIND: LogKind = LogKind::$kind;
            fn log(&self, channels: &LogChannels, nanos: u64) {
                channels.channels.$field.log_with_time(self, nanos);
            }
        }
    };
}

log_message!(proto::State, State, state);
log_message!(proto::Reference, Reference, reference);
log_message!(proto::Planner, Planner, planner);
log_message!(proto::Control, Control, control);
log_message!(proto::Allocation, Allocation, allocation);
log_message!(proto::Actuators, Actuators, actuators);
log_message!(proto::Lyapunov, Lyapunov, lyapunov);
log_message!(proto::Hover, Hover, hover);
log_message!(proto::Fault, Fault, fault);
log_message!(FrameTransform, FrameTransform, tf);
log_message!(SceneUpdate, Scene, scene);

impl LogChannels {
    /// Writes `msg` at simulation time `t` (s) on its channel.
    pub fn write<M: LogMessage>(&mut self, t: f64, msg: &M) {
        msg.log(self, nanos(t));
        self.written.fetch_add(1, Ordering::Relaxed);
    }
}
