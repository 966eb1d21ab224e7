//! The guard's construction: the model built once, the boot rule of
//! [`crate::memory`] applied (cold, warm, corrupt record), the first outputs
//! before any sample. Never fails: unusable parameters give a CONFIG fault
//! and a permanently fail-safe guard.

use super::state::{Hold, NvHealth, Phase};
use super::{recovery_ticks, CoreSlot, GuardConfig, GuardOf, Output, DRAIN_C_UNKNOWN};
use crate::faults::{self, ChannelSet, Faults};
use crate::memory::Restore;
use crate::model::ModelInputN;
use crate::num::Num;
use crate::params::{N_NODES, TICKS_PER_STEP};
use crate::protection::{alarm_update_with, LngBudget, Valve};
use crate::trace::{RestoreKind, Trace, TraceBuf};

/// Invariant kept by every place that latches a fault: `latched != 0` implies the
/// valve is commanded open, so the per-tick fast path needs no fail-safe check.
impl<N: Num> GuardOf<N> {
    /// Builds the model once (matrix exponential) and applies the boot rule of
    /// [`crate::memory`]. Never fails: unusable parameters give a CONFIG fault and a
    /// permanently fail-safe guard (valve open, alarm, derate).
    pub fn new(config: &GuardConfig, restore: Restore) -> Self {
        let mut g = core::mem::MaybeUninit::uninit();
        Self::new_in(&mut g, config, restore);
        // SAFETY: `new_in` initialised every field.
        unsafe { g.assume_init() }
    }

    /// [`GuardOf::new`] written in place into `slot` (the firmware keeps the
    /// guard in a static: the boot stack holds no copy of it or its model).
    #[inline(never)]
    pub fn new_in<'a>(slot: &'a mut core::mem::MaybeUninit<Self>, config: &GuardConfig, restore: Restore) -> &'a mut Self {
        /// Writes fields of the struct behind a raw pointer.
        macro_rules! put {
            ($p:expr, $($f:ident : $v:expr),* $(,)?) => { $( core::ptr::addr_of_mut!((*$p).$f).write($v); )* };
        }
        let p = slot.as_mut_ptr();
        // SAFETY: `p` points to `slot`, valid for writes; `Core::init_in` and
        // `put!` write every field exactly once before the reference is made.
        let g = unsafe {
            let ok = CoreSlot::<N>::init_in(core::ptr::addr_of_mut!((*p).core), config);
            put!(p,
            latched: if ok { Faults::NONE } else { faults::CONFIG },
            dwell_model_steps: config.valve.dwell_ticks.div_ceil(TICKS_PER_STEP),
            stale_ticks: config.stale_ticks,
            startup_timeout_ticks: config.startup_timeout_ticks,
            clear_valid_ticks: config.clear_valid_ticks,
            bad_ch: ChannelSet::NONE,
            prev: [N::ZERO; 6],
            prev_ok: ChannelSet::NONE,
            gap_ok: ChannelSet::NONE,
            blind: false,
            waited: 0,
            replay_u: ModelInputN { current_ha: N::ZERO, p_a_hbar: N::ZERO, p_b_hbar: N::ZERO, speed_hrads: N::ZERO, dpos_mm: N::ZERO, ambient_c: N::ZERO },
            missing: 0,
            valid_since: 0,
            phase: Phase::WaitingCold,
            mark: 0,
            open_acc: 0,
            credit_acc: 0,
            last_cj: 0,
            // Open from boot: the safe state while the guard waits for its first sample.
            valve: Valve::open(),
            fb: None,
            supply: None,
            min_supply_bar: config.lng.min_supply_bar,
            speed: if ok { crate::speedcheck::SpeedCheck::new(&config.speed, config.model) } else { None },
            fb_mismatch: 0,
            mismatch_ticks: config.actuator_mismatch_ticks,
            lng_empty: false,
            alarm: false,
            untrusted: false,
            hold: Hold::None,
            recovery_ticks: recovery_ticks(config.model),
            lng: LngBudget::new(&config.lng),
            lng_low: false,
            tick: 0,
            out: Output {
                drain_c: DRAIN_C_UNKNOWN,
                ..Output::default()
            },
            epoch: 0,
            nv: NvHealth::Good,
            trace: TraceBuf::new(),
            );
            &mut *p
        };
        let kind = match restore {
            Restore::Cold => RestoreKind::Cold,
            Restore::Warm(r) | Restore::PowerLoss(r) => {
                let power_loss = matches!(restore, Restore::PowerLoss(_));
                g.phase = if power_loss { Phase::WaitingAfterPowerLoss } else { Phase::WaitingRestored };
                if let Some(c) = g.core.get_mut() {
                    c.model.set_temperatures(&r.temps_c, r.ambient_c);
                }
                g.lng.set_used_cj(r.lng_used_cj);
                let saved = Faults::from_bits(r.faults);
                g.latched |= saved & faults::LATCHED & !faults::CONFIG;
                g.bad_ch = saved.channel_set();
                if r.valve_open() {
                    // The valve was open: it stays open for at least its dwell.
                    g.valve.force_open();
                }
                // Saved before a clear restored trust: still not trusted; saved
                // while recovering from an unknown start: the hold starts again.
                g.untrusted = saved.contains(faults::UNTRUSTED);
                if saved.contains(faults::RECOVERING) {
                    g.hold = Hold::Pending;
                }
                if let Some(c) = g.core.get_mut() {
                    c.model.set_loss_max(g.latched.contains(faults::SENSOR_DISAGREE));
                }
                if power_loss {
                    RestoreKind::PowerLoss
                } else {
                    RestoreKind::Warm
                }
            }
            Restore::Corrupt => {
                let t = config.alarm.alarm_c;
                if let Some(c) = g.core.get_mut() {
                    c.model.set_temperatures(&[t; N_NODES], t);
                }
                g.phase = Phase::WaitingRestored;
                g.lng.set_used_cj(u32::MAX);
                g.latched |= faults::MEMORY_CORRUPT;
                g.untrusted = true;
                g.hold = Hold::Pending;
                RestoreKind::Corrupt
            }
        };
        g.trace.write(Trace::Restore { tick: 0, kind });
        g.lng_empty = g.lng.is_empty();
        g.boot_outputs();
        g
    }

    /// Outputs before the first sample: the restored estimate (none on a cold boot)
    /// with the alarm evaluated on it; no model, no alarm and derate on: CONFIG.
    #[cold]
    #[inline(never)]
    fn boot_outputs(&mut self) {
        match self.core.get() {
            Some(c) if self.phase != Phase::WaitingCold => {
                let d = c.drain_c();
                let f = d.to_f32();
                self.out.drain_c = if f.is_finite() { f } else { DRAIN_C_UNKNOWN };
                let raised = if self.untrusted {
                    self.alarm = true;
                    true
                } else {
                    alarm_update_with(&mut self.alarm, d, c.th.alarm, c.th.clear) == Some(true)
                };
                if raised {
                    self.trace.write(Trace::Alarm { tick: 0, drain_c: self.out.drain_c });
                }
            }
            Some(_) => {}
            None => self.alarm = true,
        }
        self.refresh_out();
    }
}
