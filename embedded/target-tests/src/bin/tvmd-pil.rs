//! Processor-in-the-loop firmware: the f32 core on an emulated Cortex-M4F (QEMU `mps2-an386`)
//! or Cortex-M7 (`mps2-an500`) serving `tvmd-sim run SCENARIO --pil cortex-m4|cortex-m7`.
//!
//! Frames (layout and kinds in the crate `tvmd-wire`, shared with tvmd-sim) arrive on the
//! boards' CMSDK UART0, which QEMU connects to its stdin/stdout (`-serial stdio`): the host
//! configures the controller once, then sends failure masks and each period's state and
//! reference; every request gets one reply (the core's whole output, a skipped cycle, a hover
//! classification or a refusal) with the request's sequence number. A malformed frame gets an
//! error reply; the host treats it, like silence, as a broken link. The firmware never exits
//! on its own: the host kills QEMU at the end of the flight.
#![no_std]
#![no_main]

use core::fmt::Write as _;
use core::panic::PanicInfo;
use core::ptr::{read_volatile, write_volatile};

use cortex_m_rt::{entry, exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hprintln};

use tvmd_wire as wire;

use wire::{Reader, WireController, Writer, MAX_PAYLOAD_BYTES};

/// CMSDK APB UART0 of the mps2 boards (AN386 and AN500 alike).
const UART0: usize = 0x4000_4000;
const DATA: usize = UART0;
const STATE: usize = UART0 + 0x04;
const CTRL: usize = UART0 + 0x08;
const INTSTATUS: usize = UART0 + 0x0c;
const BAUDDIV: usize = UART0 + 0x10;
const TX_FULL: u32 = 1;
const RX_FULL: u32 = 2;
/// CTRL: transmitter, receiver and receive interrupt enabled.
const TX_RX_RX_INTERRUPT: u32 = 0b1011;
/// UART0's receive interrupt is IRQ 0 on both boards; NVIC set-enable and clear-pending.
const NVIC_ISER0: usize = 0xe000_e100;
const NVIC_ICPR0: usize = 0xe000_e280;

fn uart_init() {
    // Interrupts stay masked (PRIMASK): the receive interrupt only wakes `wfi`, no handler runs.
    cortex_m::interrupt::disable();
    // SAFETY: the UART's and the NVIC's registers on both boards; this firmware is their only
    // user.
    unsafe {
        write_volatile(BAUDDIV as *mut u32, 16);
        write_volatile(CTRL as *mut u32, TX_RX_RX_INTERRUPT);
        write_volatile(NVIC_ISER0 as *mut u32, 1);
    }
}

/// Waits for a byte asleep (`wfi` until the receive interrupt is pending) rather than polling
/// the status register: a polling vCPU contends with QEMU's I/O thread for its global lock on
/// every register read and slows the link down several times.
fn read_byte() -> u8 {
    // SAFETY: as in `uart_init`.
    unsafe {
        while read_volatile(STATE as *const u32) & RX_FULL == 0 {
            // A byte arriving after the check leaves the interrupt pending: `wfi` returns.
            cortex_m::asm::wfi();
        }
        let b = read_volatile(DATA as *const u32) as u8;
        write_volatile(INTSTATUS as *mut u32, RX_FULL);
        write_volatile(NVIC_ICPR0 as *mut u32, 1);
        b
    }
}

fn write_bytes(bytes: &[u8]) {
    for b in bytes {
        // SAFETY: as in `uart_init`.
        unsafe {
            while read_volatile(STATE as *const u32) & TX_FULL != 0 {}
            write_volatile(DATA as *mut u32, u32::from(*b));
        }
    }
}

/// A message formatted into a fixed buffer (truncated when longer).
struct Text {
    buf: [u8; 256],
    len: usize,
}

impl Text {
    fn new() -> Self {
        Self {
            buf: [0; 256],
            len: 0,
        }
    }

    fn bytes(&self) -> &[u8] {
        self.buf.get(..self.len).unwrap_or(&[])
    }
}

impl core::fmt::Write for Text {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        for b in s.bytes() {
            if let Some(slot) = self.buf.get_mut(self.len) {
                *slot = b;
                self.len += 1;
            }
        }
        Ok(())
    }
}

/// Sends one frame: `words`, then `text` zero-padded to a whole word.
fn send(kind: u16, seq: u16, words: &[u32], text: &[u8]) {
    let mut payload = [0u8; MAX_PAYLOAD_BYTES];
    let mut len = 0;
    for w in words {
        if let Some(slot) = payload.get_mut(len..len + 4) {
            slot.copy_from_slice(&w.to_le_bytes());
            len += 4;
        }
    }
    for b in text {
        if let Some(slot) = payload.get_mut(len) {
            *slot = *b;
            len += 1;
        }
    }
    let len = len.div_ceil(4) * 4;
    let body = payload.get(..len).unwrap_or(&[]);
    let header = wire::frame_header(kind, seq, len as u32);
    write_bytes(&header);
    write_bytes(body);
    write_bytes(&wire::frame_crc(&header, body).to_le_bytes());
}

fn send_error(seq: u16, why: &str) {
    send(wire::KIND_ERROR, seq, &[], why.as_bytes());
}

fn send_text(kind: u16, seq: u16, words: &[u32], message: impl core::fmt::Display) {
    let mut t = Text::new();
    let _ = write!(t, "{message}");
    send(kind, seq, words, t.bytes());
}

/// One request: kind, sequence number, payload words (`Err`: why it is malformed).
fn receive(words: &mut [u32; MAX_PAYLOAD_BYTES / 4]) -> (u16, u16, Result<usize, &'static str>) {
    // Hunt for the magic: after a desync the next frame still parses.
    let mut header = [0u8; wire::FRAME_HEADER_BYTES];
    let mut matched = 0;
    while matched < 4 {
        let b = read_byte();
        matched = if Some(&b) == wire::FRAME_MAGIC.get(matched) {
            matched + 1
        } else {
            usize::from(Some(&b) == wire::FRAME_MAGIC.first())
        };
    }
    header[..4].copy_from_slice(&wire::FRAME_MAGIC);
    for b in header.iter_mut().skip(4) {
        *b = read_byte();
    }
    let kind = u16::from_le_bytes([header[4], header[5]]);
    let seq = u16::from_le_bytes([header[6], header[7]]);
    let len = u32::from_le_bytes([header[8], header[9], header[10], header[11]]) as usize;
    if !len.is_multiple_of(4) || len > MAX_PAYLOAD_BYTES {
        return (kind, seq, Err("bad payload length"));
    }
    let mut payload = [0u8; MAX_PAYLOAD_BYTES];
    let body = payload.get_mut(..len).unwrap_or(&mut []);
    for b in body.iter_mut() {
        *b = read_byte();
    }
    let crc = u32::from_le_bytes([read_byte(), read_byte(), read_byte(), read_byte()]);
    if crc != wire::frame_crc(&header, body) {
        return (kind, seq, Err("checksum mismatch"));
    }
    for (w, c) in words.iter_mut().zip(body.chunks_exact(4)) {
        *w = u32::from_le_bytes([c[0], c[1], c[2], c[3]]);
    }
    (kind, seq, Ok(len / 4))
}

/// Answers one well-formed request.
fn serve(kind: u16, seq: u16, words: &[u32], ctl: &mut Option<(WireController, usize)>) {
    let mut r = Reader::new(words);
    let mut out = [0u32; MAX_PAYLOAD_BYTES / 4];
    match (kind, ctl.as_mut()) {
        (wire::KIND_CONFIGURE, _) => match wire::CoreConfig::get(&mut r) {
            None => send_error(seq, "malformed configuration"),
            Some(config) => match config.build() {
                Ok(c) => {
                    *ctl = Some((c, config.n));
                    send(wire::KIND_CONFIGURED, seq, &[config.n as u32], &[]);
                }
                Err(e) => send_text(wire::KIND_REFUSED, seq, &[], e),
            },
        },
        (wire::KIND_SET_FAILURES, Some((c, _))) => match r.u32() {
            None => send_error(seq, "malformed failure mask"),
            Some(bits) => match c.set_failures(wire::mask_of(bits)) {
                Ok(hover) => {
                    let mut w = Writer::new(&mut out);
                    let _ = wire::put_hover(&mut w, &hover);
                    let len = w.len();
                    send(wire::KIND_HOVER, seq, out.get(..len).unwrap_or(&[]), &[]);
                }
                Err(e) => send_text(wire::KIND_REFUSED, seq, &[], e),
            },
        },
        (wire::KIND_SET_LANDED, Some((c, _))) => match r.u32() {
            Some(flag @ (0 | 1)) => {
                c.set_landed(flag == 1);
                send(wire::KIND_LANDED, seq, &[flag], &[]);
            }
            _ => send_error(seq, "malformed landed flag"),
        },
        (wire::KIND_STEP, Some((c, n))) => match wire::get_input(&mut r) {
            None => send_error(seq, "malformed cycle inputs"),
            Some((state, reference)) => {
                let mut w = Writer::new(&mut out);
                let (reply, written) = match c.step(&state, &reference) {
                    Ok(o) => (Ok(()), wire::put_output(&mut w, &o, *n)),
                    Err(e) => (Err(e), wire::put_commands(&mut w, &e.commands, *n)),
                };
                let fault = wire::FaultAnswer {
                    report: c.fault_report().copied(),
                    masking: c.fault_masking(),
                    failures: *c.failures(),
                };
                let written = written.and_then(|()| wire::put_fault_answer(&mut w, &fault));
                let len = w.len();
                let words = out.get(..len).unwrap_or(&[]);
                match (reply, written) {
                    (_, None) => send_error(seq, "output too large"),
                    (Ok(()), Some(())) => send(wire::KIND_OUTPUT, seq, words, &[]),
                    (Err(e), Some(())) => send_text(wire::KIND_SKIPPED, seq, words, e),
                }
            }
        },
        (wire::KIND_SET_FAILURES | wire::KIND_SET_LANDED | wire::KIND_STEP, None) => {
            send_error(seq, "controller not configured")
        }
        _ => send_error(seq, "unknown request kind"),
    }
}

#[entry]
fn main() -> ! {
    uart_init();
    send(wire::KIND_READY, 0, &[wire::PROTOCOL_VERSION], &[]);
    let mut ctl: Option<(WireController, usize)> = None;
    let mut words = [0u32; MAX_PAYLOAD_BYTES / 4];
    loop {
        let (kind, seq, len) = receive(&mut words);
        match len {
            Ok(len) => serve(kind, seq, words.get(..len).unwrap_or(&[]), &mut ctl),
            Err(why) => send_error(seq, why),
        }
    }
}

#[panic_handler]
fn panic(info: &PanicInfo<'_>) -> ! {
    hprintln!("tvmd-pil: panic: {}", info);
    debug::exit(debug::EXIT_FAILURE);
    #[allow(clippy::empty_loop)]
    loop {}
}

/// A fault ends the run at once (QEMU exits; the host reports the closed link).
#[exception]
unsafe fn HardFault(frame: &ExceptionFrame) -> ! {
    hprintln!("tvmd-pil: hard fault at pc {:#010x}", frame.pc());
    debug::exit(debug::EXIT_FAILURE);
    #[allow(clippy::empty_loop)]
    loop {}
}
