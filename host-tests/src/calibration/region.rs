//! An operating region of a log (time, speed, Δp and drain ranges) and
//! the bench run that would put it into the training set: what refusals,
//! the margin's validation and the training envelope name.

/// An operating region of a log: ranges over the ticks that matter.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Region {
    /// Time, s.
    pub t_s: (f64, f64),
    /// Shaft speed (absolute), rpm.
    pub speed_rpm: (f64, f64),
    /// Port pressure difference (absolute), bar.
    pub dp_bar: (f64, f64),
    /// Drain temperature of the reference, °C.
    pub drain_c: (f64, f64),
    /// Whether the log is a servo run (its circuit by
    /// [`crate::simulation::replay::circuit_of`]).
    pub servo: bool,
}

impl std::fmt::Display for Region {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} run, t {:.0}–{:.0} s, {:.0}–{:.0} rpm, Δp {:.0}–{:.0} bar, drain {:.1}–{:.1} °C",
            if self.servo { "servo" } else { "throttle" },
            self.t_s.0,
            self.t_s.1,
            self.speed_rpm.0,
            self.speed_rpm.1,
            self.dp_bar.0,
            self.dp_bar.1,
            self.drain_c.0,
            self.drain_c.1
        )
    }
}

/// One replay tick kept for the regions: t s, |speed| rpm, |Δp| bar,
/// reference drain °C.
pub type TickRow = (f64, f64, f64, f64);

impl Region {
    /// The empty region (every range from +max to −max), to be widened.
    pub fn empty(servo: bool) -> Self {
        let e = (f64::MAX, f64::MIN);
        Region { t_s: e, speed_rpm: e, dp_bar: e, drain_c: e, servo }
    }

    /// Widened to hold tick `r`.
    pub fn widen(&mut self, r: &TickRow) {
        let w = |a: &mut (f64, f64), x: f64| *a = (a.0.min(x), a.1.max(x));
        w(&mut self.t_s, r.0);
        w(&mut self.speed_rpm, r.1);
        w(&mut self.dp_bar, r.2);
        w(&mut self.drain_c, r.3);
    }

    /// Widened to hold `other` too.
    pub fn join(&mut self, other: &Region) {
        self.widen(&(other.t_s.0, other.speed_rpm.0, other.dp_bar.0, other.drain_c.0));
        self.widen(&(other.t_s.1, other.speed_rpm.1, other.dp_bar.1, other.drain_c.1));
    }

    /// The bench run that would put this region into the training set with
    /// the drain logged.
    pub fn bench_run(&self) -> String {
        if self.servo {
            format!(
                "a 30-min servo hold/manoeuvre mission in the training set (holds and triangles reaching Δp {:.0}–{:.0} bar), with `t_drain_c` logged",
                self.dp_bar.0, self.dp_bar.1
            )
        } else {
            format!(
                "a 30-min throttle run holding {:.0} rpm at {:.0} bar until the drain passes {:.0} °C, then speed and needle stepped one at a time around that point, with `t_drain_c` logged",
                0.5 * (self.speed_rpm.0 + self.speed_rpm.1),
                0.5 * (self.dp_bar.0 + self.dp_bar.1),
                self.drain_c.1
            )
        }
    }
}
