//! What the controller may ask of the guard between ticks: outputs, faults
//! and their clear rule, actuator and valve reports, LNG refill, the
//! thermal record and the trace.

use super::*;

impl<N: Num> GuardOf<N> {
    /// The outputs as the last tick left them (at boot: the waiting state).
    pub fn output(&self) -> Output {
        self.out
    }

    /// Present faults (see [`faults`]).
    pub fn faults(&self) -> Faults {
        self.latched
            | Faults::channels(self.bad_ch)
            | Faults::when(self.lng_low, faults::LNG_LOW)
            | Faults::when(self.untrusted, faults::UNTRUSTED)
            | Faults::when(self.nv.failed(), faults::NV_FAILED)
            | Faults::when(self.recovering(), faults::RECOVERING)
            | self.cooling_status()
    }

    /// Ticks the estimate still needs to forget an unknown start (0: it
    /// has, or it started from a known state). Before the first sample an
    /// unknown start has not begun to recover.
    pub fn recovery_left(&self) -> u32 {
        match self.hold {
            Hold::Pending => self.recovery_ticks,
            Hold::From(t) => self.recovery_ticks.saturating_sub(self.tick.wrapping_sub(t)),
            Hold::None => 0,
        }
    }

    fn recovering(&self) -> bool {
        self.recovery_left() > 0
    }

    /// Why the cooling is not (or not fully) confirmed, while the valve is
    /// commanded open: no position report since samples started (no credit), no supply pressure
    /// (credit on the budget alone), or a supply pressure below its minimum
    /// (the tank is empty: no credit, LNG_LOW).
    fn cooling_status(&self) -> Faults {
        let open = self.valve.is_open();
        Faults::when(open && self.phase.started() && self.fb.is_none(), faults::NO_VALVE_FEEDBACK)
            | Faults::when(open && self.fb == Some(true) && self.supply.is_none() && self.credited(), faults::LNG_UNCONFIRMED)
            | Faults::when(self.supply == Some(false), faults::LNG_LOW)
    }

    /// Reports the LNG supply pressure at the valve, bar gauge (`None`: not
    /// reported), once per tick before [`GuardOf::tick`]. Below
    /// `LngConfig::min_supply_bar` (or NaN) the tank is taken as empty: no
    /// cooling credit, LNG_LOW. Without the report the tank is taken as full
    /// until the LNG budget says it is empty, and flagged LNG_UNCONFIRMED
    /// (residual risk: docs/firmware.md).
    pub fn lng_supply(&mut self, bar: Option<f32>) {
        let s = bar.map(|p| p >= self.min_supply_bar);
        if s != self.supply {
            // The credit changes from this tick on: count the ticks before.
            self.settle(self.tick);
            self.supply = s;
            self.refresh_out();
        }
    }

    /// Speed plausibility on this tick's sample and the motor's electrical
    /// frequency, if reported ([`crate::speedcheck`]), once per tick before
    /// [`GuardOf::tick`]. An implausible speed latches SENSOR_DISAGREE with
    /// the speed channel bad (its worst case from this tick on), opens the
    /// valve and holds the alarm until a clear.
    pub fn check_speed(&mut self, s: &Sample, elec_hz: Option<f32>) {
        let Some(sc) = self.speed.as_mut() else { return };
        if sc.tick(s, elec_hz) {
            self.latch_speed();
        }
    }

    #[cold]
    #[inline(never)]
    fn latch_speed(&mut self) {
        self.settle(self.tick);
        let newly = !self.latched.contains(faults::SENSOR_DISAGREE) || !self.bad_ch.intersects(ChannelSet::SPEED);
        self.latched |= faults::SENSOR_DISAGREE;
        self.bad_ch |= ChannelSet::SPEED;
        self.untrusted = true;
        if newly {
            self.trace.write(Trace::Fault { tick: self.tick, new_bits: faults::SENSOR_DISAGREE | Faults::channels(ChannelSet::SPEED) });
        }
        if self.valve.force_open() {
            self.trace.write(Trace::ValveOpen { tick: self.tick, drain_c: self.out.drain_c, forced: true });
        }
        self.refresh_out();
    }

    /// The board's report of a non-volatile save of the thermal record: a
    /// failure raises NV_FAILED with derate at once (after a power loss the
    /// restore could be older than the write policy promises); it clears
    /// at the next clear that follows a good save.
    pub fn report_nv_save(&mut self, ok: bool) {
        match (ok, self.nv) {
            (true, NvHealth::Failed) => self.nv = NvHealth::SavedSince,
            (true, _) => {}
            (false, NvHealth::Good) => {
                self.nv = NvHealth::Failed;
                self.trace.write(Trace::Fault { tick: self.tick, new_bits: faults::NV_FAILED });
                self.refresh_out();
            }
            (false, _) => self.nv = NvHealth::Failed,
        }
    }

    /// **Clear rule.** Latched faults (except CONFIG) clear only through this explicit
    /// call (maintenance / operator command), and only if the last
    /// `clear_valid_ticks` samples (1 s by default) were all valid and none is missing.
    /// The thermal estimate is *not* reset: it relaxes from its conservative value.
    /// A clear also restores trust in the estimate ([`faults::UNTRUSTED`]: after a
    /// STALE dropout the estimate ran on every channel's worst case), **except**
    /// while the estimate is still recovering from an unknown state
    /// ([`faults::RECOVERING`], [`super::recovery_ticks`]: an unknown start,
    /// counted from the first sample, or inputs that disagreed, counted from
    /// this clear): then the faults clear and UNTRUSTED holds
    /// ([`ClearResult::TrustHeld`]).
    pub fn clear_faults(&mut self) -> ClearResult {
        let valid_run = self.tick.wrapping_sub(self.valid_since);
        if self.missing != 0 || valid_run < self.clear_valid_ticks {
            return ClearResult::Refused;
        }
        let bits = (self.latched & !faults::CONFIG) | Faults::channels(self.bad_ch);
        self.settle(self.tick);
        self.latched &= faults::CONFIG;
        self.bad_ch = ChannelSet::NONE;
        // A valve still disagreeing with its command latches again after the full time;
        // so do sensors that still disagree.
        self.fb_mismatch = 0;
        if let Some(c) = self.core.get_mut() {
            if let Some(cc) = c.cc.as_mut() {
                cc.restart_count();
                // the step in progress summed the cleared channels' worst cases
                if c.model.pending_ticks() > 0 && bits.channel_set().intersects(CROSS_CHANNELS) {
                    cc.taint_step();
                }
                c.model.set_loss_max(cc.disagrees());
            }
        }
        if let Some(sc) = self.speed.as_mut() {
            sc.restart();
        }
        // The controller accepts the estimate as it is (it is not reset); the alarm
        // follows it again from the next model step — unless it is still recovering
        // from an unknown state: after a disagreement that recovery starts now,
        // with the inputs good again.
        if self.hold == Hold::Pending && self.phase.started() {
            self.hold = Hold::From(self.tick);
        }
        let left = self.recovery_left();
        let trust = left == 0 && self.untrusted;
        let bits = bits | Faults::when(trust, faults::UNTRUSTED) | Faults::when(self.nv == NvHealth::SavedSince, faults::NV_FAILED);
        if left == 0 {
            self.untrusted = false;
            self.hold = Hold::None;
        }
        if self.nv == NvHealth::SavedSince {
            self.nv = NvHealth::Good;
        }
        if !bits.is_empty() {
            self.trace.write(Trace::FaultsCleared {
                tick: self.tick,
                bits,
            });
        }
        self.refresh_out();
        if self.untrusted {
            ClearResult::TrustHeld(left)
        } else {
            ClearResult::Cleared
        }
    }

    /// Marks an actuator (valve pin) error reported by the board: latches ACTUATOR
    /// and commands the valve open at once (fail-safe).
    pub fn report_actuator_fault(&mut self) {
        self.settle(self.tick);
        if !self.latched.contains(faults::ACTUATOR) {
            self.latched |= faults::ACTUATOR;
            self.trace.write(Trace::Fault {
                tick: self.tick,
                new_bits: faults::ACTUATOR,
            });
        }
        if self.valve.force_open() {
            self.trace.write(Trace::ValveOpen {
                tick: self.tick,
                drain_c: self.out.drain_c,
                forced: true,
            });
        }
        self.refresh_out();
    }

    /// Reports the valve position read back from the valve (limit switch or
    /// position sensor), `true` = open. Optional; when used, call it once per tick,
    /// before [`GuardOf::tick`] / [`GuardOf::tick_missing`] (the position holds until
    /// the next report). The model credits the exchanger only while the report does
    /// not say shut; `actuator_mismatch_ticks` consecutive reports that differ from
    /// the command latch ACTUATOR (valve forced open, no credit). Without reports the
    /// command is taken as the position (residual risk: docs/firmware.md).
    pub fn valve_feedback(&mut self, open: bool) {
        if self.fb != Some(open) {
            // The credit may change from this tick on: count the ticks before.
            self.settle(self.tick);
            self.fb = Some(open);
            self.refresh_out();
        }
        if open == self.valve.is_open() {
            self.fb_mismatch = 0;
            return;
        }
        self.fb_mismatch = self.fb_mismatch.saturating_add(1);
        if self.fb_mismatch >= self.mismatch_ticks {
            self.report_actuator_fault();
        }
    }

    /// Refills the LNG budget (new charge installed).
    pub fn refill_lng(&mut self, cfg: &LngConfig) {
        // The credit may change from this tick on: count the ticks before.
        self.settle(self.tick);
        self.lng = LngBudget::new(cfg);
        self.lng_empty = self.lng.is_empty();
        self.lng_low = false;
        self.refresh_out();
    }

    /// Thermal-memory record of the present state, valve state included
    /// (sealed with its CRC; sequence number 0: the writer sets it).
    pub fn snapshot(&self) -> ThermalRecord {
        let r = self.snapshot_unsealed();
        r.with_seq(r.seq(), r.valve_open())
    }

    /// [`GuardOf::snapshot`] without its CRC, for a writer that seals it
    /// ([`crate::memory::slots::AbWriter::write`]): one CRC per record.
    pub fn snapshot_unsealed(&self) -> ThermalRecord {
        let mut temps = [0.0f32; N_NODES];
        let mut amb = 0.0;
        if let Some(c) = self.core.get() {
            for (o, t) in temps.iter_mut().zip(c.model.temperatures_c().iter()) {
                *o = t.to_f32();
            }
            amb = c.model.ambient_c().to_f32();
        }
        let mut r = ThermalRecord::unsealed(temps, amb, self.lng.used_cj(), (self.faults() & faults::RECORDED).bits(), self.tick);
        r.seq_flags = if self.valve.is_open() { crate::memory::FLAG_VALVE_OPEN } else { 0 };
        r
    }

    /// Counts every change of the outputs or of the state the thermal record
    /// holds (model step, fault latched or cleared, valve, LNG refill): a
    /// record written at one value of it is still current while it holds.
    pub fn epoch(&self) -> u32 {
        self.epoch
    }

    /// The event trace (most recent [`crate::trace::TRACE_LEN`] events).
    pub fn trace(&self) -> &TraceBuf {
        &self.trace
    }

    /// Appends a board-level event (overrun, reset, command) to the trace.
    pub fn trace_event(&mut self, t: Trace) {
        self.trace.write(t);
    }

    /// Refuses the configuration after boot (an invalid parameter block):
    /// CONFIG latches and the model is disabled, as for constants the model
    /// rejects at init: valve open, alarm, drain reported as
    /// [`DRAIN_C_UNKNOWN`]. CONFIG is never cleared.
    pub fn refuse_config(&mut self) {
        self.core.ok = false;
        self.latched |= faults::CONFIG;
        // fail-safe outputs from this instant: valve open, alarm (OK pin low),
        // no estimate
        self.valve.force_open();
        self.alarm = true;
        self.out.drain_c = DRAIN_C_UNKNOWN;
        self.refresh_out();
    }

    /// The model, when the parameters were usable.
    pub fn model(&self) -> Option<&Model<N>> {
        self.core.get().map(|c| &c.model)
    }

    /// Ticks taken since boot (10 ms each, wraps after 497 days).
    pub fn ticks(&self) -> u32 {
        self.tick
    }
}
