//! Software in the loop: the product application on the host, on the shared
//! in-memory board ([`MemBoard`]), fed the same bytes per tick as the PIL
//! image in QEMU: the bit-for-bit twin of the firmware.

use eha_guard::num::{Fx, Num};
use eha_guard::product::mem_board::MemBoard;
use eha_guard::product::wire::FromGuard;
use eha_guard::product::AppOf;
use eha_guard::protocol::Deframer;
use eha_guard::GuardConfig;

use super::{tick_out, PilError, Target, TickOut};

/// The application of one number type on an in-memory board.
pub struct AppTarget<N: Num> {
    app: AppOf<N>,
    /// The board (records, non-volatile store, pins, clock).
    pub board: Box<MemBoard>,
}

impl<N: Num> AppTarget<N> {
    /// Boots the application on `board` with `cfg` (from what the board's
    /// memories hold).
    pub fn boot(cfg: &GuardConfig, mut board: Box<MemBoard>) -> Self {
        let mem = board.boot_memory();
        let app = AppOf::<N>::boot(&mut *board, cfg, &mem);
        board.clear_tx();
        AppTarget { app, board }
    }

    /// The application (read only).
    pub fn app(&self) -> &AppOf<N> {
        &self.app
    }

    /// Gives the board back (to boot again from what it keeps).
    pub fn into_board(self) -> Box<MemBoard> {
        self.board
    }
}

/// Decodes the frames in `bytes` (sent by the application).
pub fn frames(bytes: &[u8]) -> Vec<FromGuard> {
    let mut d = Deframer::new();
    let mut out = Vec::new();
    for &b in bytes {
        if let Some(Ok(p)) = d.push(b) {
            if let Ok(f) = FromGuard::from_payload(p) {
                out.push(f);
            }
        }
    }
    out
}

impl<N: Num> Target for AppTarget<N> {
    fn tick(&mut self, rx: &[u8], tick: u64) -> Result<TickOut, PilError> {
        if self.board.push_rx(rx) < rx.len() {
            return Err(PilError::Protocol { tick, what: "more bytes in one tick than the board's receive buffer holds".into() });
        }
        self.app.tick(&mut *self.board, 0);
        let sent = self.board.take_tx();
        tick_out(frames(&sent), 0).ok_or_else(|| PilError::Protocol { tick, what: "the host application sent no tick reply".into() })
    }
}

/// The host twin of the PIL image for `build`: the same application with
/// the same number type, configuration and boot (cold: QEMU starts with
/// zeroed RAM), on the in-memory board.
pub struct SilTarget(Box<dyn Target>);

impl SilTarget {
    /// The twin of the `build` image.
    pub fn new(build: super::Build) -> Self {
        Self::with_config(build, &GuardConfig::DEFAULT)
    }

    /// The twin with another configuration (e.g. a commissioned machine's
    /// constants, other thresholds).
    pub fn with_config(build: super::Build, cfg: &GuardConfig) -> Self {
        let board = Box::new(MemBoard::new());
        match build {
            super::Build::F32 => SilTarget(Box::new(AppTarget::<f32>::boot(cfg, board))),
            super::Build::Fixed => SilTarget(Box::new(AppTarget::<Fx>::boot(cfg, board))),
        }
    }
}

impl Target for SilTarget {
    fn tick(&mut self, rx: &[u8], tick: u64) -> Result<TickOut, PilError> {
        self.0.tick(rx, tick)
    }
}
