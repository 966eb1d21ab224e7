//! The 10 ms tick: a sample (or its absence) is validated, substituted by its
//! worst case where it is bad, and accumulated into the model's tick; every
//! [`crate::params::TICKS_PER_STEP`] ticks it hands over to the model step
//! (`step.rs`).

use super::*;

impl<N: Num> GuardOf<N> {
    /// One 10 ms tick with a new sample and the controller's reports, in the
    /// product loop's order: the valve position (when reported), the LNG
    /// supply, the speed plausibility, then [`GuardOf::tick`].
    #[inline(always)]
    pub fn tick_reported(&mut self, s: &Sample, r: &Reports) -> Output {
        if let Some(open) = r.valve_fb {
            self.valve_feedback(open);
        }
        self.lng_supply(r.lng_supply_bar);
        self.check_speed(s, r.elec_hz);
        self.tick(s)
    }

    /// One 10 ms tick with a new sample. Never panics; any invalid channel latches a
    /// fault, opens the valve in this same tick and is replaced by its worst case.
    #[inline(never)]
    pub fn tick(&mut self, s: &Sample) -> Output {
        if let Some(core) = self.core.get() {
            // Fast path: every channel in range and within its rate and every previous
            // value valid (so this is not the first tick). Nothing to latch, the valve
            // is not forced by this tick (an earlier latched fault has already opened
            // it), the outputs only change at a model step. Channels latched bad by an
            // earlier fault still take their worst case. Anything else is classified
            // by `tick_slow`.
            let (v, ok) = validate::convert_check(s, &self.prev, &core.scales, &core.limits);
            if ok & (self.prev_ok == ChannelSet::ALL) {
                // `missing` is 0 here: a missing tick clears `prev_ok`.
                let u = if self.bad_ch.is_empty() {
                    validate::direct(&v, &self.prev)
                } else {
                    let [_, _, _, _, prev_pos, _] = self.prev;
                    Self::subst(&v, self.bad_ch, Some(prev_pos), &core.limits)
                };
                self.prev = v;
                return self.advance(&u);
            }
        }
        self.tick_slow(s)
    }

    /// [`validate::substitute`], one copy for every caller off the
    /// per-tick fast path (flash): a sample's channels with the `bad` ones
    /// at their worst case.
    #[inline(never)]
    #[cold]
    fn subst(v: &Channels<N>, bad: ChannelSet, prev_pos: Option<N>, limits: &LimitsN<N>) -> ModelInputN<N> {
        validate::substitute(v, bad, prev_pos, limits)
    }

    /// [`GuardOf::tick`] off the fast path: classifies the sample (distinct fault and
    /// channel bits), substitutes worst cases, latches and forces the valve open.
    #[inline(never)]
    #[cold]
    fn tick_slow(&mut self, s: &Sample) -> Output {
        let gap = core::mem::replace(&mut self.missing, 0);
        let first = !self.phase.started();
        let Some(core) = self.core.get() else {
            return self.slow_tail(None, Faults::NONE, N::ZERO);
        };
        let (v, nonfinite) = validate::convert(s, &core.scales);
        // After missing ticks (samples slower than the tick, or a dropout
        // shorter than STALE) the rate is checked over the gap: the limits
        // times the ticks since the last sample.
        let over_gap;
        let (ok_before, lim) = if gap > 0 && gap < self.stale_ticks {
            over_gap = core.limits.rate_over(gap + 1);
            (self.gap_ok, &over_gap)
        } else {
            (self.prev_ok, &core.limits)
        };
        let c = validate::check(&v, nonfinite, &self.prev, ok_before, lim);
        let mut new_bits = Faults::NONE;
        if c.range {
            new_bits |= faults::RANGE;
        }
        if c.rate {
            new_bits |= faults::RATE;
        }
        if c.non_finite {
            new_bits |= faults::NON_FINITE;
        }
        self.bad_ch |= c.bad;
        if !c.bad.is_empty() {
            self.valid_since = self.tick.wrapping_add(1);
        }
        let [_, _, _, _, prev_pos, _] = self.prev;
        let prev_pos = if self.prev_ok.intersects(ChannelSet::POSITION) {
            Some(prev_pos)
        } else {
            None
        };
        let u = Self::subst(&v, self.bad_ch, prev_pos, &core.limits);
        if first {
            // The ticks waited for this first sample, replayed at its start
            // with its own inputs (its own bad channels at their worst case;
            // not the STALE substitution of a timeout: that says nothing
            // about what the machine did).
            self.waited = gap;
            self.replay_u = Self::subst(&v, c.bad, None, &core.limits);
        }
        // A cold start takes this sample's own ambient when it is valid (also when
        // an earlier STALE makes the model run on the worst case from now on), else
        // the worst case.
        let [_, _, _, _, _, amb] = v;
        let start_amb = if !c.bad.intersects(ChannelSet::AMBIENT) { amb } else { u.ambient_c };
        self.prev = v;
        self.prev_ok = !c.bad;
        self.slow_tail(Some(&u), new_bits, start_amb)
    }

    /// One 10 ms tick without a new sample: inputs are held (piston work taken as
    /// zero); after `stale_ticks` consecutive misses the STALE fault latches and every
    /// channel takes its worst case. Before the first sample the guard waits instead
    /// (`wait_tick`).
    pub fn tick_missing(&mut self) -> Output {
        if !self.phase.started() {
            return self.wait_tick();
        }
        self.missing = self.missing.saturating_add(1);
        self.valid_since = self.tick.wrapping_add(1);
        if self.missing == 1 {
            self.gap_ok = self.prev_ok;
        }
        self.prev_ok = ChannelSet::NONE;
        let mut new_bits = Faults::NONE;
        if self.missing >= self.stale_ticks {
            new_bits |= faults::STALE;
            self.bad_ch = ChannelSet::ALL;
            self.stale_alarm();
        }
        let u = self.core.get().map(|c| Self::subst(&self.prev, self.bad_ch, None, &c.limits));
        self.slow_tail(u.as_ref(), new_bits, N::ZERO)
    }

    /// `n` ticks the MCU did not see at all: a flash erase stalled the core
    /// (the board's timer counted them, no sample was read). Accounted as
    /// missing ticks are before STALE — the last inputs held, latched
    /// channels at their worst case, no piston work (all pump power heats)
    /// — and with no cooling credit; the clear rule's valid run and the rate
    /// check restart; not counted towards STALE (the controller did not go
    /// silent, the guard did). Every channel at its worst case instead
    /// would heat the paper rig's drain estimate by 35 K per second of gap
    /// (measured, `tests/core/stall.rs`): every erase an alarm. The residual
    /// risk (a load rise inside the gap) is in docs/firmware.md, "Flash
    /// erase stall". Before the first sample: waiting ticks. The product
    /// loop caps `n` at [`crate::product::MAX_STALL_TICKS`].
    #[cold]
    #[inline(never)]
    pub fn tick_blind(&mut self, n: u32) -> Output {
        if !self.phase.started() {
            for _ in 0..n {
                self.wait_tick();
            }
            return self.out;
        }
        self.settle(self.tick);
        self.blind = true;
        for _ in 0..n {
            self.valid_since = self.tick.wrapping_add(1);
            self.prev_ok = ChannelSet::NONE;
            self.gap_ok = ChannelSet::NONE;
            let u = self.core.get().map(|c| Self::subst(&self.prev, self.bad_ch, None, &c.limits));
            self.slow_tail(u.as_ref(), Faults::NONE, N::ZERO);
        }
        self.settle(self.tick);
        self.blind = false;
        self.out
    }

    /// STALE after the start: the controller went silent, the machine may
    /// run on unseen; the alarm and the derate at once, held until a clear
    /// (the estimate runs on every channel's worst case meanwhile, so the
    /// clear restores trust at once: no unknown start).
    #[cold]
    #[inline(never)]
    fn stale_alarm(&mut self) {
        self.untrusted = true;
        if !self.alarm {
            self.alarm = true;
            self.trace.write(Trace::Alarm { tick: self.tick, drain_c: self.out.drain_c });
        }
    }

    /// A tick without a sample before the first sample (boot, or samples not yet
    /// flowing): the model is not started and accumulates nothing, the valve stays
    /// open; after `startup_timeout_ticks` such ticks STALE latches (every channel
    /// worst case once samples arrive, until a clear).
    #[cold]
    #[inline(never)]
    fn wait_tick(&mut self) -> Output {
        self.missing = self.missing.saturating_add(1);
        self.valid_since = self.tick.wrapping_add(1);
        if self.missing >= self.startup_timeout_ticks {
            if !self.latched.contains(faults::STALE) {
                self.trace.write(Trace::Fault {
                    tick: self.tick,
                    new_bits: faults::STALE | Faults::channels(ChannelSet::ALL),
                });
            }
            self.latched |= faults::STALE;
            self.bad_ch = ChannelSet::ALL;
            // No estimate and no input: alarm and derate until a clear, and
            // the machine may have run unseen: the start state is unknown.
            self.untrusted = true;
            self.hold = Hold::Pending;
            if !self.alarm {
                self.alarm = true;
                self.trace.write(Trace::Alarm {
                    tick: self.tick,
                    drain_c: self.out.drain_c,
                });
            }
        }
        // The valve is open since boot (nothing closes it before the first sample).
        self.refresh_out();
        self.tick = self.tick.wrapping_add(1);
        self.mark = self.tick;
        self.out
    }

    /// Slow-path tail: latches `new_bits` and opens the valve at once when any fault
    /// is latched (fail-safe in the same tick), starts the model at the first sample
    /// (cold: at `start_amb`), then the common tick.
    fn slow_tail(&mut self, u: Option<&ModelInputN<N>>, new_bits: Faults, start_amb: N) -> Output {
        // The valve / credit state may change for this tick: count the ticks before.
        self.settle(self.tick);
        let newly = new_bits & !self.latched;
        self.latched |= new_bits;
        if !newly.is_empty() {
            self.trace.write(Trace::Fault {
                tick: self.tick,
                new_bits: newly | Faults::channels(self.bad_ch),
            });
        }
        if !self.latched.is_empty() && self.valve.force_open() {
            self.trace.write(Trace::ValveOpen {
                tick: self.tick,
                drain_c: self.out.drain_c,
                forced: true,
            });
        }
        match u {
            Some(u) if self.core.get().is_some() => {
                if !self.phase.started() {
                    self.start(start_amb);
                    self.replay_wait();
                }
                self.refresh_out();
                self.advance_slow(u)
            }
            _ => {
                // No model (CONFIG): fail-safe outputs, nothing to estimate.
                self.alarm = true;
                self.out.drain_c = DRAIN_C_UNKNOWN;
                self.refresh_out();
                self.tick = self.tick.wrapping_add(1);
                self.out
            }
        }
    }

    /// The ticks the guard waited for its first sample (at most the
    /// start-up timeout): the machine may have run meanwhile, unseen. They
    /// are replayed at the first sample with its inputs (no piston work:
    /// the first sample has no position derivative), no cooling credit:
    /// the machine is taken to have done then what it does now. Not
    /// counting them, a controller starting 5 s late on a machine at 60 bar
    /// would leave the estimate 1.2 K low.
    #[cold]
    #[inline(never)]
    fn replay_wait(&mut self) {
        let n = core::mem::replace(&mut self.waited, 0).min(self.startup_timeout_ticks);
        if n == 0 {
            return;
        }
        let u = self.replay_u;
        let now = self.tick;
        self.tick = now.wrapping_sub(n);
        self.mark = self.tick;
        self.blind = true;
        for _ in 0..n {
            self.advance_slow(&u);
        }
        self.settle(self.tick);
        self.blind = false;
        self.tick = now;
    }

    /// [`GuardOf::advance`] off the fast path: one copy of the model's tick
    /// accumulation for the slow paths (flash).
    #[inline(never)]
    fn advance_slow(&mut self, u: &ModelInputN<N>) -> Output {
        self.advance(u)
    }

    /// The per-tick part common to both paths: the model's tick accumulation, and
    /// every `TICKS_PER_STEP` ticks the model step with the protection.
    #[inline(always)]
    fn advance(&mut self, u: &ModelInputN<N>) -> Output {
        let full = match self.core.get_mut() {
            Some(c) => c.model.tick_n(u),
            None => false,
        };
        if full {
            self.model_step();
        }
        self.tick = self.tick.wrapping_add(1);
        self.out
    }
}
