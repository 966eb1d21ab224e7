//! Decoding the firmware's defmt log on the host with `defmt-decoder`.

use std::path::Path;

use anyhow::{anyhow, Context, Result};

/// One decoded log line.
#[derive(Clone, Debug, PartialEq)]
pub struct LogLine {
    /// The defmt timestamp: the firmware's tick count at the time.
    pub tick: Option<u64>,
    /// Log level as defmt prints it (`INFO`, `WARN`, ...).
    pub level: String,
    /// The formatted message.
    pub message: String,
}

impl std::fmt::Display for LogLine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.tick {
            Some(s) => write!(f, "tick {s:>6} {:<5} {}", self.level, self.message),
            None => write!(f, "{:<5} {}", self.level, self.message),
        }
    }
}

/// Decode the raw defmt stream `bytes` with the tables of the ELF at `elf`.
/// Undecodable bytes are reported as a final `ERROR` line rather than dropped.
pub fn decode(elf: &Path, bytes: &[u8]) -> Result<Vec<LogLine>> {
    let image = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let table = defmt_decoder::Table::parse(&image)
        .map_err(|e| anyhow!("defmt table of {}: {e}", elf.display()))?
        .ok_or_else(|| anyhow!("{} has no defmt table (.defmt section)", elf.display()))?;
    let mut dec = table.new_stream_decoder();
    dec.received(bytes);
    let mut lines = Vec::new();
    loop {
        match dec.decode() {
            Ok(frame) => {
                let tick = frame.display_timestamp().and_then(|t| t.to_string().trim().parse::<u64>().ok());
                lines.push(LogLine {
                    tick,
                    level: frame.level().map_or("PRINT".to_string(), |l| l.as_str().to_uppercase()),
                    message: frame.display_message().to_string(),
                });
            }
            Err(defmt_decoder::DecodeError::UnexpectedEof) => break,
            Err(defmt_decoder::DecodeError::Malformed) => {
                lines.push(LogLine {
                    tick: None,
                    level: "ERROR".into(),
                    message: "malformed defmt frame in the log stream (bytes lost)".into(),
                });
                if table.encoding().can_recover() {
                    continue;
                }
                break;
            }
        }
    }
    Ok(lines)
}
