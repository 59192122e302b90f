//! Live view: a run's log served over Foxglove's WebSocket protocol by the SDK's server, so the
//! Foxglove app (`Open connection` -> `ws://127.0.0.1:8765`) shows the team as it flies.
//!
//! The server publishes the simulation time (the `time` capability), so the app's clock
//! follows the run; [`LiveServer::pace`] holds the run to real time.

use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use foxglove::websocket::Capability;
use foxglove::{Context, WebSocketServerHandle};

use crate::LogError;

/// Where and how a run is served live.
#[derive(Clone, Debug, PartialEq)]
pub struct LiveOptions {
    /// Address to bind; `127.0.0.1` (this machine only). `0.0.0.0` exposes the run to the
    /// network.
    pub host: String,
    /// Port; 8765 (Foxglove's default). 0 picks a free port.
    pub port: u16,
    /// Simulated seconds per wall second; 1 (real time), in [0.001, 1e6].
    pub speed: f64,
    /// Before flying, wait up to this long (s) for a client to connect; 0 flies at once.
    pub wait_for_client: f64,
}

impl Default for LiveOptions {
    fn default() -> Self {
        Self {
            host: "127.0.0.1".into(),
            port: 8765,
            speed: 1.0,
            wait_for_client: 0.0,
        }
    }
}

impl LiveOptions {
    /// Checks the options (typed errors naming the option).
    pub fn validate(&self) -> Result<(), LogError> {
        let bad = |name: &str, reason: String| {
            Err(LogError::InvalidArgument {
                name: name.into(),
                reason,
            })
        };
        if !(1e-3..=1e6).contains(&self.speed) {
            return bad(
                "live speed",
                format!("must be in [0.001, 1e6] x real time, got {}", self.speed),
            );
        }
        if !(self.wait_for_client.is_finite() && (0.0..=86_400.0).contains(&self.wait_for_client)) {
            return bad(
                "live wait",
                format!("must be in [0, 86400] s, got {}", self.wait_for_client),
            );
        }
        if self.host.trim().is_empty() {
            return bad("live host", "is empty".into());
        }
        Ok(())
    }
}

/// A running live server and the run's pace.
pub struct LiveServer {
    handle: WebSocketServerHandle,
    address: SocketAddr,
    speed: f64,
    wait: f64,
    /// Wall time of simulated time 0, set at the first [`LiveServer::pace`].
    start: Option<Instant>,
}

impl LiveServer {
    /// Starts the SDK's server on `context` (the run's own).
    pub fn start(context: &Arc<Context>, options: &LiveOptions) -> Result<Self, LogError> {
        options.validate()?;
        let handle = context
            .websocket_server()
            .name(concat!("tvmd-sim ", env!("CARGO_PKG_VERSION")))
            .bind(options.host.clone(), options.port)
            .capabilities([Capability::Time])
            .start_blocking()
            .map_err(|e| LogError::InvalidArgument {
                name: "live".into(),
                reason: format!("cannot serve on {}:{}: {e}", options.host, options.port),
            })?;
        let ip = options
            .host
            .parse()
            .unwrap_or(std::net::IpAddr::from([127, 0, 0, 1]));
        Ok(Self {
            address: SocketAddr::new(ip, handle.port()),
            handle,
            speed: options.speed,
            wait: options.wait_for_client,
            start: None,
        })
    }

    /// Waits up to [`LiveOptions::wait_for_client`] for a client to connect, or until
    /// `cancel` is set.
    pub fn wait_for_client(&self, cancel: Option<&AtomicBool>) {
        // `wait` was validated in [0, 86400] s by `start`.
        let deadline = Instant::now() + Duration::from_secs_f64(self.wait);
        while self.client_count() == 0
            && Instant::now() < deadline
            && !cancel.is_some_and(|c| c.load(Ordering::Relaxed))
        {
            std::thread::sleep(Duration::from_millis(20));
        }
    }

    /// The address the server listens on.
    pub fn address(&self) -> SocketAddr {
        self.address
    }

    /// Connected clients.
    pub fn client_count(&self) -> usize {
        self.handle.client_count()
    }

    /// Publishes simulated time `t` (s) and sleeps until the wall clock has caught up with it
    /// at the configured speed.
    pub fn pace(&mut self, t: f64) {
        self.handle.broadcast_time(crate::nanos(t));
        let start = *self.start.get_or_insert_with(Instant::now);
        let due = start + Duration::from_secs_f64((t / self.speed).max(0.0));
        let now = Instant::now();
        if due > now {
            std::thread::sleep(due - now);
        }
    }

    /// Stops the server (connected clients are closed).
    pub fn stop(self) {
        // Dropping the shutdown handle lets the server's tasks finish on their own.
        let _ = self.handle.stop();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_options_are_refused_by_name() {
        let mut o = LiveOptions {
            speed: 0.0,
            ..LiveOptions::default()
        };
        assert!(
            matches!(o.validate(), Err(LogError::InvalidArgument { name, .. }) if name == "live speed")
        );
        o.speed = 1.0;
        o.wait_for_client = f64::NAN;
        assert!(o.validate().is_err());
        o.wait_for_client = 0.0;
        assert!(o.validate().is_ok());
    }

    #[test]
    fn a_server_binds_a_free_port_and_paces_to_the_wall_clock() {
        let ctx = Context::new();
        let mut s = LiveServer::start(
            &ctx,
            &LiveOptions {
                port: 0,
                speed: 10.0,
                ..LiveOptions::default()
            },
        )
        .unwrap();
        assert_ne!(s.address().port(), 0);
        let t0 = Instant::now();
        s.pace(0.0);
        s.pace(0.5); // 0.05 s of wall time at 10x
        assert!(t0.elapsed() >= Duration::from_millis(50));
        s.stop();
    }
}
