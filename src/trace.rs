//! Event trace: a fixed-size ring buffer of protection events (hubris-style
//! `Trace` enum), kept in RAM and readable by a debugger or over defmt.

use heapless::Deque;

/// Capacity of the trace ring buffer, events (oldest are overwritten).
pub const TRACE_LEN: usize = 32;

/// How the thermal state was initialised at boot (see [`crate::memory`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum RestoreKind {
    /// Cold boot: every node starts at the first ambient sample.
    Cold,
    /// Warm/watchdog reset: a valid record was restored.
    Warm,
    /// A record was present but failed its magic/CRC/plausibility check:
    /// conservative start (every node at the alarm temperature, valve open).
    Corrupt,
    /// Power loss: the non-volatile record was restored (raised by the write
    /// policy's margin; cooled over the off-time where a clock measured it).
    PowerLoss,
}

/// One protection event. `tick` is the guard's tick counter (10 ms) at the event;
/// temperatures are the predicted drain temperature in degC.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Trace {
    /// Thermal state initialised (cold / warm / corrupt record).
    Restore {
        /// Tick counter (10 ms).
        tick: u32,
        /// Kind of start.
        kind: RestoreKind,
    },
    /// LNG valve commanded open (threshold crossed or forced by a fault).
    ValveOpen {
        /// Tick counter (10 ms).
        tick: u32,
        /// Predicted drain temperature, degC.
        drain_c: f32,
        /// `true` when a fault forced it, `false` when the temperature did.
        forced: bool,
    },
    /// LNG valve commanded closed (below the closing threshold for the whole dwell).
    ValveClose {
        /// Tick counter (10 ms).
        tick: u32,
        /// Predicted drain temperature, degC.
        drain_c: f32,
    },
    /// Over-temperature alarm raised (drain > alarm threshold): derate requested.
    Alarm {
        /// Tick counter (10 ms).
        tick: u32,
        /// Predicted drain temperature, degC.
        drain_c: f32,
    },
    /// Over-temperature alarm cleared (drain below alarm threshold - hysteresis).
    AlarmClear {
        /// Tick counter (10 ms).
        tick: u32,
        /// Predicted drain temperature, degC.
        drain_c: f32,
    },
    /// New fault bits latched (see [`crate::faults`]).
    Fault {
        /// Tick counter (10 ms).
        tick: u32,
        /// Faults newly set this tick (with the latched channels).
        new_bits: crate::faults::Faults,
    },
    /// Latched faults cleared by the explicit clear rule.
    FaultsCleared {
        /// Tick counter (10 ms).
        tick: u32,
        /// Faults that were cleared.
        bits: crate::faults::Faults,
    },
    /// LNG remaining fell below the low threshold.
    LngLow {
        /// Tick counter (10 ms).
        tick: u32,
        /// Remaining LNG, kg.
        remaining_kg: f32,
    },
    /// A tick overran its 10 ms period (product loop, [`crate::product`]).
    Overrun {
        /// Tick counter (10 ms).
        tick: u32,
        /// Timer periods that elapsed during the tick beyond its own.
        lost_ticks: u16,
    },
    /// The MCU came out of a reset ([`crate::product::wire::ResetCause`] code).
    Reset {
        /// Tick counter (10 ms).
        tick: u32,
        /// Reset cause code.
        cause: u8,
    },
    /// A controller command was executed ([`crate::product::wire::Cmd`] code).
    Command {
        /// Tick counter (10 ms).
        tick: u32,
        /// Command code.
        code: u8,
        /// 0 done, else why refused (`product::wire::Refusal`).
        result: u8,
    },
    /// Where this boot's model constants come from
    /// ([`crate::params_block::ParamSource::code`]: 0 compiled-in default,
    /// 1 parameter block, 2.. invalid block).
    Params {
        /// Tick counter (10 ms).
        tick: u32,
        /// Source code.
        source: u8,
    },
}

/// Ring buffer of the most recent [`TRACE_LEN`] events (oldest dropped when full).
///
/// Built on `heapless::Deque`, whose accessors are unchecked internally, so that the
/// tick path has no bounds-check panic (`HistoryBuf::write` indexes with a check).
#[derive(Clone, Debug, Default)]
pub struct TraceBuf {
    q: Deque<Trace, TRACE_LEN>,
}

impl TraceBuf {
    /// Empty buffer.
    pub const fn new() -> Self {
        TraceBuf { q: Deque::new() }
    }

    /// Appends an event, dropping the oldest when full.
    pub fn write(&mut self, t: Trace) {
        if self.q.is_full() {
            let _ = self.q.pop_front();
        }
        // Cannot fail: there is room after the pop above.
        let _ = self.q.push_back(t);
    }

    /// Events, oldest first.
    pub fn iter(&self) -> impl Iterator<Item = &Trace> {
        self.q.iter()
    }

    /// Most recent event.
    pub fn recent(&self) -> Option<&Trace> {
        self.q.back()
    }

    /// Number of stored events.
    pub fn len(&self) -> usize {
        self.q.len()
    }

    /// `true` when no event is stored.
    pub fn is_empty(&self) -> bool {
        self.q.is_empty()
    }
}
