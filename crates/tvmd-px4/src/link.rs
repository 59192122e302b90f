//! The simulator link: the TCP port PX4's `simulator_mavlink` connects to (4560 + instance),
//! MAVLink 2 frames of the common dialect both ways, every wait bounded by a wall-clock timeout.

use std::io::ErrorKind;
use std::net::{Ipv4Addr, SocketAddr, TcpListener, TcpStream};
use std::time::{Duration, Instant};

use mavlink::dialects::common::MavMessage;
use mavlink::error::MessageReadError;
use mavlink::{MavHeader, MavlinkReader, MavlinkVersion};

use crate::Px4Error;

/// PX4's simulator port of instance 0.
pub const BASE_PORT: u16 = 4560;

/// How often a wait looks again (accept, read).
const POLL: Duration = Duration::from_millis(2);

/// The simulator's MAVLink identity: system 1 (PX4's own), component 51 (the one jMAVSim and
/// Gazebo use; PX4 does not filter the simulator link).
pub const SIM_HEADER: MavHeader = MavHeader {
    system_id: 1,
    component_id: 51,
    sequence: 0,
};

/// A listening simulator port, before PX4 connects.
pub struct Listener {
    listener: TcpListener,
    port: u16,
}

impl Listener {
    /// Listens on `127.0.0.1:port` (0: any free port, for tests). Errors: the port is in use
    /// or refused ([`Px4Error::Bind`]).
    pub fn bind(port: u16) -> Result<Self, Px4Error> {
        let address = SocketAddr::from((Ipv4Addr::LOCALHOST, port));
        let listener =
            TcpListener::bind(address).map_err(|source| Px4Error::Bind { port, source })?;
        let port = listener
            .local_addr()
            .map_err(|source| Px4Error::Bind { port, source })?
            .port();
        listener
            .set_nonblocking(true)
            .map_err(|source| Px4Error::Bind { port, source })?;
        Ok(Self { listener, port })
    }

    /// The port listened on.
    pub fn port(&self) -> u16 {
        self.port
    }

    /// Waits up to `timeout` for PX4 to connect; `keep_waiting()` is asked between polls (a
    /// child PX4 that exited stops the wait with its own error).
    pub fn accept(
        self,
        timeout: Duration,
        keep_waiting: &mut dyn FnMut() -> Result<(), Px4Error>,
    ) -> Result<SimLink, Px4Error> {
        let start = Instant::now();
        loop {
            match self.listener.accept() {
                Ok((stream, _)) => return SimLink::new(stream, self.port),
                Err(e) if e.kind() == ErrorKind::WouldBlock => {}
                Err(source) => {
                    return Err(Px4Error::Link {
                        what: format!("accept on port {}", self.port),
                        source,
                    })
                }
            }
            if start.elapsed() >= timeout {
                return Err(Px4Error::NeverConnected {
                    port: self.port,
                    waited: start.elapsed().as_secs_f64(),
                });
            }
            keep_waiting()?;
            std::thread::sleep(POLL * 5);
        }
    }
}

/// What a read from PX4 gave.
pub enum Received {
    /// A message (boxed: a MAVLink message is up to 280 bytes).
    Message(Box<MavMessage>),
    /// Nothing before the deadline.
    Timeout,
    /// PX4 closed the connection.
    Closed,
}

/// A connected simulator link.
pub struct SimLink {
    writer: TcpStream,
    reader: MavlinkReader<TcpStream>,
    sequence: u8,
    port: u16,
    slice: Option<Duration>,
}

impl SimLink {
    fn new(stream: TcpStream, port: u16) -> Result<Self, Px4Error> {
        let io = |what: &str| {
            let what = format!("{what} on port {port}");
            move |source| Px4Error::Link { what, source }
        };
        stream.set_nonblocking(false).map_err(io("blocking mode"))?;
        stream.set_nodelay(true).map_err(io("TCP_NODELAY"))?;
        stream
            .set_read_timeout(Some(POLL))
            .map_err(io("read timeout"))?;
        let reader = MavlinkReader::new(stream.try_clone().map_err(io("clone"))?);
        Ok(Self {
            writer: stream,
            reader,
            sequence: 0,
            port,
            slice: None,
        })
    }

    /// Reads without blocking, a wait sleeping `slice` between looks (the real-time bridge:
    /// a socket's read timeout counts in the kernel's ticks, up to 4 ms, a period of PX4's
    /// sensors). Writes then fail rather than wait when PX4 stops reading.
    pub fn set_nonblocking(&mut self, slice: Duration) -> Result<(), Px4Error> {
        self.writer
            .set_nonblocking(true)
            .map_err(|source| Px4Error::Link {
                what: format!("non-blocking mode on port {}", self.port),
                source,
            })?;
        self.slice = Some(slice);
        Ok(())
    }

    /// The port of the link.
    pub fn port(&self) -> u16 {
        self.port
    }

    /// Sends one message.
    pub fn send(&mut self, message: &MavMessage) -> Result<(), Px4Error> {
        let header = MavHeader {
            sequence: self.sequence,
            ..SIM_HEADER
        };
        self.sequence = self.sequence.wrapping_add(1);
        match mavlink::write_versioned_msg(&mut self.writer, MavlinkVersion::V2, header, message) {
            Ok(_) => Ok(()),
            Err(mavlink::error::MessageWriteError::Io(e)) if is_closed(&e) => {
                Err(Px4Error::Disconnected { t: f64::NAN })
            }
            Err(e) => Err(Px4Error::Link {
                what: format!("send on port {}", self.port),
                source: std::io::Error::other(e.to_string()),
            }),
        }
    }

    /// The next message, waiting until `deadline` at most.
    pub fn recv_until(&mut self, deadline: Instant) -> Result<Received, Px4Error> {
        loop {
            match self.reader.read_any_message::<MavMessage>() {
                Ok((_, message)) => return Ok(Received::Message(Box::new(message))),
                Err(MessageReadError::Io(e))
                    if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) =>
                {
                    let now = Instant::now();
                    if now >= deadline {
                        return Ok(Received::Timeout);
                    }
                    if let Some(slice) = self.slice {
                        std::thread::sleep(slice.min(deadline - now));
                    }
                }
                Err(MessageReadError::Io(e)) if is_closed(&e) => return Ok(Received::Closed),
                // A frame of a message outside the common dialect, or a bad CRC: skipped.
                Err(MessageReadError::Parse(_)) => {}
                Err(MessageReadError::Io(source)) => {
                    return Err(Px4Error::Link {
                        what: format!("receive on port {}", self.port),
                        source,
                    })
                }
            }
        }
    }
}

fn is_closed(e: &std::io::Error) -> bool {
    matches!(
        e.kind(),
        ErrorKind::UnexpectedEof
            | ErrorKind::ConnectionReset
            | ErrorKind::ConnectionAborted
            | ErrorKind::BrokenPipe
    )
}
