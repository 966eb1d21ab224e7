//! The 100 ms model step and the protection on its estimate: start-up,
//! LNG credit, the model update, the sensor cross-check, valve, alarm and
//! LNG budget, and the outputs.

use super::*;

impl<N: Num> GuardOf<N> {
    /// First sample: a cold start takes every node to `ambient_c`; the valve leaves
    /// the open start-up state by the hysteresis relay on the initial (or restored)
    /// estimate (closed only below the closing threshold, with no qualification: the
    /// opening was not temperature-driven), then the protection is evaluated once.
    #[cold]
    #[inline(never)]
    pub(super) fn start(&mut self, ambient_c: N) {
        let from = core::mem::replace(&mut self.phase, Phase::Running);
        if self.hold == Hold::Pending {
            // The estimate starts to forget its unknown start from here.
            self.hold = Hold::From(self.tick);
        }
        // Nothing of the waiting time is counted: no model ran, no credit, no LNG booked.
        self.mark = self.tick;
        self.open_acc = 0;
        self.credit_acc = 0;
        let Some(c) = self.core.get_mut() else {
            return;
        };
        if from == Phase::WaitingCold {
            c.model.set_uniform(ambient_c);
        } else if from == Phase::WaitingAfterPowerLoss {
            // The air may have been warmer during the off-time than at the save:
            // every node is raised by the first sample's excess over the saved
            // ambient (the cooling bound assumes the larger of the two).
            let rise = ambient_c.sub(c.model.ambient_c());
            if rise > N::ZERO {
                let t = c.model.temperatures_c().map(|x| x.add(rise).to_f32());
                c.model.set_temperatures(&t, ambient_c.to_f32());
            }
        }
        let d = c.drain_c();
        if self.latched.is_empty() && d < c.th.close && self.valve.is_open() {
            self.valve.set(false);
            self.trace.write(Trace::ValveClose {
                tick: self.tick,
                drain_c: d.to_f32(),
            });
        }
        self.protect(0, 0);
    }

    /// Adds the ticks from `mark` up to (not including) `upto` to the open / credited
    /// counts in the present valve and fault state. Called before anything changes
    /// that state, so the counts need no per-tick work: the valve command changes
    /// only at a model step and on the slow path (forced open), the credit also when
    /// faults latch or clear.
    pub(super) fn settle(&mut self, upto: u32) {
        let n = upto.wrapping_sub(self.mark);
        if self.valve.is_open() {
            self.open_acc = self.open_acc.wrapping_add(n);
            if self.credited() {
                self.credit_acc = self.credit_acc.wrapping_add(n);
            }
        }
        self.mark = upto;
    }

    /// The exchanger is credited (with the valve commanded open): only when
    /// the cooling is confirmed — the valve's position report says open,
    /// the supply pressure (if reported) says the tank has LNG, the LNG
    /// budget is not used up — and no fault is latched (conservative: the
    /// exchanger itself may be what failed).
    #[inline(always)]
    pub(super) fn credited(&self) -> bool {
        self.latched.is_empty() && !self.lng_empty && self.fb == Some(true) && self.supply != Some(false) && !self.blind
    }

    /// Every `TICKS_PER_STEP` ticks: the model step, then the protection.
    #[inline(never)]
    pub(super) fn model_step(&mut self) {
        // This tick belongs to the model step that ends now, in the state it had.
        self.settle(self.tick.wrapping_add(1));
        let (open_ticks, credit_ticks) = (self.open_acc, self.credit_acc);
        self.open_acc = 0;
        self.credit_acc = 0;
        let Some(c) = self.core.get_mut() else {
            return;
        };
        c.model.update(credit_ticks);
        // Mean total loss kW → cJ per 10 ms tick (= W), never negative.
        let cj = c.model.last_total_kw().round_times(1000).max(0) as u32;
        if let Some(cc) = c.cc.as_mut() {
            let (from_p, from_i) = c.model.last_mech_pair_kw();
            match cc.step(from_p, from_i, !self.bad_ch.intersects(CROSS_CHANNELS)) {
                Verdict::None => {}
                // While they disagree (and once latched) the model heats with the
                // larger of the two losses.
                Verdict::Window(d) => c.model.set_loss_max(d || self.latched.contains(faults::SENSOR_DISAGREE)),
                Verdict::Latch => {
                    c.model.set_loss_max(true);
                    self.latch_disagree();
                }
            }
        }
        // The valid run of the clear rule is `tick - valid_since`; keep it from
        // wrapping (2^30 ticks = 124 days is far above any clear_valid_ticks).
        if self.tick.wrapping_sub(self.valid_since) > 1 << 30 {
            self.valid_since = self.tick.wrapping_sub(1 << 30);
        }
        self.protect(cj, open_ticks);
    }

    /// The current and the pressures / speed have disagreed for `persist_windows`
    /// windows: SENSOR_DISAGREE latches (the valve opens in `protect`, this same
    /// tick) and the estimate is not trusted (alarm and derate until a clear).
    #[cold]
    #[inline(never)]
    fn latch_disagree(&mut self) {
        if !self.latched.contains(faults::SENSOR_DISAGREE) {
            self.latched |= faults::SENSOR_DISAGREE;
            self.trace.write(Trace::Fault {
                tick: self.tick,
                new_bits: faults::SENSOR_DISAGREE,
            });
        }
        self.untrusted = true;
        // The estimate ran on inputs that disagree (the larger shaft loss
        // covers the shaft, not the throttling heat a wrong pressure hides):
        // its state is unknown until it has recovered on good inputs.
        self.hold = Hold::Pending;
    }

    /// Valve hysteresis and dwell, alarm, LNG budget (`open_ticks` ticks of the model
    /// step with the valve open, at `cj` centijoules per tick) and the outputs that
    /// change only here.
    fn protect(&mut self, cj: u32, open_ticks: u32) {
        let Some(c) = self.core.get() else {
            return;
        };
        let force = !self.latched.is_empty();
        let d = c.drain_c();
        let th = &c.th;
        let valve_ev = self
            .valve
            .update_with(d, force, th.open, th.close, self.dwell_model_steps);
        let alarm_ev = if self.untrusted {
            // Held whatever the estimate says (raised at boot or at the timeout).
            (!core::mem::replace(&mut self.alarm, true)).then_some(true)
        } else {
            alarm_update_with(&mut self.alarm, d, th.alarm, th.clear)
        };
        let drain_c = d.to_f32();
        let drain_c = if drain_c.is_finite() {
            drain_c
        } else {
            DRAIN_C_UNKNOWN
        };
        self.out.drain_c = drain_c;
        if let Some(open) = valve_ev {
            let t = if open {
                Trace::ValveOpen {
                    tick: self.tick,
                    drain_c,
                    forced: force,
                }
            } else {
                Trace::ValveClose {
                    tick: self.tick,
                    drain_c,
                }
            };
            self.trace.write(t);
        }
        if let Some(a) = alarm_ev {
            let t = if a {
                Trace::Alarm {
                    tick: self.tick,
                    drain_c,
                }
            } else {
                Trace::AlarmClear {
                    tick: self.tick,
                    drain_c,
                }
            };
            self.trace.write(t);
        }
        self.lng.update_cj_ticks(cj, open_ticks);
        // The credit state of the ticks from here on (`settle` ran for the step's).
        self.lng_empty = self.lng.is_empty();
        self.last_cj = cj;
        let low = self.lng.is_low();
        if low && !self.lng_low {
            self.trace.write(Trace::LngLow {
                tick: self.tick,
                remaining_kg: self.lng.remaining_kg(),
            });
        }
        self.lng_low = low;
        self.refresh_out();
    }

    /// Rebuilds the cached outputs from the present state (one copy: it
    /// runs at model steps and state changes, never on the tick's fast path).
    #[inline(never)]
    pub(super) fn refresh_out(&mut self) {
        self.epoch = self.epoch.wrapping_add(1);
        // Derate: the alarm, and whatever leaves the protection weaker than
        // the estimate says (a valve not following its command, a thermal
        // record that could not be saved).
        let derate = self.alarm || self.nv.failed() || self.latched.contains(faults::ACTUATOR);
        self.out = Output {
            drain_c: self.out.drain_c,
            valve_open: self.valve.is_open(),
            alarm: self.alarm,
            derate,
            faults: self.faults(),
            lng_remaining_kg: self.lng.remaining_kg(),
            lng_seconds_left: self.lng.seconds_left_cj(self.last_cj),
        };
    }
}
