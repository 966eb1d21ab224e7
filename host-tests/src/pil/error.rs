//! Why a PIL session failed, in words: the firmware's exit codes and the
//! harness's error type (shared by the QEMU and SIL targets).

use std::time::Duration;

/// Exit codes of the firmware (`boards/mps2/src/bin/eha-fw.rs`).
pub fn exit_meaning(code: i32) -> &'static str {
    match code {
        0 => "clean exit",
        2 => "firmware panic",
        3 => "firmware HardFault",
        4 => "unexpected exception/interrupt (DefaultHandler)",
        5 => "firmware could not read stdin (or a chunk was cut short)",
        6 => "firmware could not write replies",
        7 => "firmware could not open semihosting stdio",
        _ => "unknown exit code (QEMU itself failed?)",
    }
}

/// Why a PIL session failed. Every variant says what happened in words.
#[derive(Debug, thiserror::Error)]
pub enum PilError {
    /// `qemu-system-arm` is not installed.
    #[error("qemu-system-arm was not found on PATH: install it (`apt-get install -y qemu-system-arm`; .ci/run does this). QEMU tests cannot run without it")]
    QemuMissing,
    /// QEMU could not be started.
    #[error("could not start QEMU: {0}")]
    Spawn(std::io::Error),
    /// No reply within the timeout (QEMU still running, then killed).
    #[error("firmware stopped answering: no reply within {waited:?} at tick {tick} (QEMU still running; killed). QEMU stderr text: {text:?}")]
    Timeout {
        /// Step whose reply was awaited.
        tick: u64,
        /// How long the harness waited.
        waited: Duration,
        /// QEMU's stderr text.
        text: String,
    },
    /// The firmware exited before the run ended.
    #[error("firmware exited abnormally at tick {tick}: exit code {code:?} ({meaning}). QEMU stderr text: {text:?}")]
    Exited {
        /// Step at which it exited.
        tick: u64,
        /// Exit code (semihosting exit or QEMU's own).
        code: Option<i32>,
        /// What the code means.
        meaning: &'static str,
        /// QEMU's stderr text.
        text: String,
    },
    /// The firmware exited without its completion marker.
    #[error("firmware exited without the completion marker (exit status {status}); the run is not trustworthy. QEMU stderr text: {text:?}")]
    NoCompletionMarker {
        /// QEMU's exit status.
        status: String,
        /// QEMU's stderr text.
        text: String,
    },
    /// A tick whose frames do not decode or do not answer the input.
    #[error("protocol error at tick {tick}: {what}")]
    Protocol {
        /// Step of the bad reply.
        tick: u64,
        /// What was wrong.
        what: String,
    },
    /// Reading from or writing to QEMU failed.
    #[error("I/O error talking to QEMU: {0}")]
    Io(#[from] std::io::Error),
}
