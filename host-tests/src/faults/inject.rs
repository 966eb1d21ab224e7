//! The faults of the campaign: what each one does to the controller's
//! samples, to the frames on the wire, to the guard's memory and to the
//! valve, from the moment it starts.

use eha_guard::validate::InputLimits;
use eha_guard::Sample;

/// An input channel of the guard's sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Channel {
    /// Motor current, A rms.
    Current,
    /// Port A pressure, bar.
    PressureA,
    /// Port B pressure, bar.
    PressureB,
    /// Motor speed, rpm.
    Speed,
    /// Piston position, mm.
    Position,
    /// Ambient temperature, °C.
    Ambient,
}

impl Channel {
    /// Every channel, in the sample's order.
    pub const ALL: [Channel; 6] =
        [Channel::Current, Channel::PressureA, Channel::PressureB, Channel::Speed, Channel::Position, Channel::Ambient];

    /// Short name used in the campaign's table.
    pub fn name(self) -> &'static str {
        match self {
            Channel::Current => "current",
            Channel::PressureA => "p_a",
            Channel::PressureB => "p_b",
            Channel::Speed => "speed",
            Channel::Position => "position",
            Channel::Ambient => "ambient",
        }
    }

    /// The channel's value in a sample.
    pub fn get(self, s: &Sample) -> f32 {
        match self {
            Channel::Current => s.current_a,
            Channel::PressureA => s.p_a_bar,
            Channel::PressureB => s.p_b_bar,
            Channel::Speed => s.speed_rpm,
            Channel::Position => s.position_mm,
            Channel::Ambient => s.ambient_c,
        }
    }

    fn set(self, s: &mut Sample, v: f32) {
        match self {
            Channel::Current => s.current_a = v,
            Channel::PressureA => s.p_a_bar = v,
            Channel::PressureB => s.p_b_bar = v,
            Channel::Speed => s.speed_rpm = v,
            Channel::Position => s.position_mm = v,
            Channel::Ambient => s.ambient_c = v,
        }
    }

    /// Full scale of the channel: the top of its plausible range
    /// (`InputLimits::DEFAULT`), in wire units.
    pub fn full_scale(self) -> f32 {
        let l = InputLimits::DEFAULT;
        match self {
            Channel::Current => l.current_a_max,
            Channel::PressureA | Channel::PressureB => l.pressure_bar_max,
            Channel::Speed => l.speed_rpm_max,
            Channel::Position => l.position_mm_max,
            Channel::Ambient => l.ambient_c_max,
        }
    }
}

/// What goes wrong with one input channel.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum InputFault {
    /// Frozen at the value it had when the fault started.
    StuckLast,
    /// Reads 0.
    StuckZero,
    /// Reads its full scale (in range).
    StuckFull,
    /// Offset by +20 % of full scale.
    BiasUp,
    /// Offset by −20 % of full scale.
    BiasDown,
    /// Reads half the true value.
    GainHalf,
    /// Reads 1.5 × the true value.
    GainOneAndHalf,
    /// Drifts towards 0 linearly over [`DRIFT_S`] (ambient: down by 20 K).
    Drift,
    /// Gaussian noise of σ = 5 % of full scale on every sample.
    Noise,
    /// NaN.
    NaN,
    /// 1.5 × full scale (out of the plausible range).
    OutOfRange,
}

/// Duration of the slow drift, s.
pub const DRIFT_S: f64 = 300.0;

impl InputFault {
    /// Every input fault.
    pub const ALL: [InputFault; 11] = [
        InputFault::StuckLast,
        InputFault::StuckZero,
        InputFault::StuckFull,
        InputFault::BiasUp,
        InputFault::BiasDown,
        InputFault::GainHalf,
        InputFault::GainOneAndHalf,
        InputFault::Drift,
        InputFault::Noise,
        InputFault::NaN,
        InputFault::OutOfRange,
    ];

    /// Short name used in the campaign's table.
    pub fn name(self) -> &'static str {
        match self {
            InputFault::StuckLast => "stuck-last",
            InputFault::StuckZero => "stuck-zero",
            InputFault::StuckFull => "stuck-full-scale",
            InputFault::BiasUp => "bias+20%",
            InputFault::BiasDown => "bias-20%",
            InputFault::GainHalf => "gain-x0.5",
            InputFault::GainOneAndHalf => "gain-x1.5",
            InputFault::Drift => "drift",
            InputFault::Noise => "noise",
            InputFault::NaN => "nan",
            InputFault::OutOfRange => "out-of-range",
        }
    }
}

/// One fault of the campaign.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Fault {
    /// No fault: the scenario as it is (the baseline of the start times).
    None,
    /// A faulty input channel.
    Input(Channel, InputFault),
    /// Bursts of lost frames: 0.5 s of every 10 s.
    DropoutBursts,
    /// The controller starts sending 5 s after the guard boots.
    LateStart,
    /// One frame in 50 has a flipped bit on the wire.
    CorruptedFrames,
    /// Every 20th pair of frames arrives swapped.
    OutOfOrderFrames,
    /// The MCU resets (watchdog, brown-out) and restores its thermal record.
    WarmReset,
    /// The whole EHA loses power for [`super::POWER_OFF_S`]: the pump
    /// stops, RAM is gone, the clock runs on; the guard boots from its
    /// non-volatile record cooled over the measured off-time.
    PowerLoss,
    /// Only the guard's MCU loses power for [`super::POWER_OFF_S`] while
    /// the machine runs on (the residual risk of the power-off cooling).
    PowerLossMachineRunning,
    /// A reset during the record write: the record reads corrupt at boot.
    TornRecordWrite,
    /// The LNG tank is empty (and the guard's budget knows it: its record
    /// says the charge is used up); the exchanger does not cool.
    LngEmpty,
    /// The tank runs physically empty (or the line blocks) at the fault's
    /// start; the guard's budget still says there is LNG.
    LngEmptyPhysical,
    /// The tank is empty and the budget knows it ([`Fault::LngEmpty`]), and
    /// the controller asks for a refill (armed, keyed) every 10 s: no new
    /// charge was installed.
    RefillWhileEmpty,
    /// The valve sticks closed whatever it is commanded.
    ValveStuckClosed,
    /// The frames stop carrying the valve's position report.
    NoValveFeedback,
    /// Every flash write fails from the start; the EHA loses power
    /// 120 s later (60 s off) and boots from what the flash still holds.
    FlashWriteFail,
    /// The EHA loses power at the start (60 s off) and the flash cannot be
    /// read at the next boot.
    FlashReadFail,
    /// A port-A pressure stuck at zero (a fault that latches) with the
    /// controller confirming a clear (armed, keyed) every second.
    ClearSpam,
    /// A reset that leaves both RAM records torn and the flash unreadable
    /// (an unknown start), the controller confirming a clear 2 s after the
    /// boot and every 10 s.
    CorruptStartClear,
}

impl Fault {
    /// Every fault of the campaign (not [`Fault::None`]: the baseline).
    pub fn all() -> Vec<Fault> {
        let mut v: Vec<Fault> =
            Channel::ALL.iter().flat_map(|&c| InputFault::ALL.iter().map(move |&f| Fault::Input(c, f))).collect();
        v.extend([
            Fault::DropoutBursts,
            Fault::LateStart,
            Fault::CorruptedFrames,
            Fault::OutOfOrderFrames,
            Fault::WarmReset,
            Fault::PowerLoss,
            Fault::PowerLossMachineRunning,
            Fault::TornRecordWrite,
            Fault::LngEmpty,
            Fault::LngEmptyPhysical,
            Fault::RefillWhileEmpty,
            Fault::ValveStuckClosed,
            Fault::NoValveFeedback,
            Fault::FlashWriteFail,
            Fault::FlashReadFail,
            Fault::ClearSpam,
            Fault::CorruptStartClear,
        ]);
        v
    }

    /// The fault is the same whenever it starts (it acts from boot): run
    /// at one start time only.
    pub fn from_boot(&self) -> bool {
        matches!(self, Fault::None | Fault::LateStart | Fault::LngEmpty | Fault::RefillWhileEmpty)
    }

    /// A fault of the speed channel (run with and without the drive's
    /// electrical frequency).
    pub fn is_speed(&self) -> bool {
        matches!(self, Fault::Input(Channel::Speed, _))
    }

    /// A fault the LNG supply pressure sees (run with and without it).
    pub fn is_supply(&self) -> bool {
        matches!(self, Fault::LngEmptyPhysical | Fault::RefillWhileEmpty)
    }

    /// Name used in the campaign's table, e.g. `current/gain-x0.5`.
    pub fn name(&self) -> String {
        match self {
            Fault::None => "none".into(),
            Fault::Input(c, f) => format!("{}/{}", c.name(), f.name()),
            Fault::DropoutBursts => "dropout-bursts".into(),
            Fault::LateStart => "late-start".into(),
            Fault::CorruptedFrames => "corrupted-frames".into(),
            Fault::OutOfOrderFrames => "out-of-order-frames".into(),
            Fault::WarmReset => "warm-reset".into(),
            Fault::PowerLoss => "power-loss".into(),
            Fault::PowerLossMachineRunning => "power-loss-machine-running".into(),
            Fault::TornRecordWrite => "torn-record-write".into(),
            Fault::LngEmpty => "lng-empty".into(),
            Fault::ValveStuckClosed => "valve-stuck-closed".into(),
            Fault::LngEmptyPhysical => "lng-empty-physical".into(),
            Fault::RefillWhileEmpty => "refill-while-empty".into(),
            Fault::NoValveFeedback => "no-valve-feedback".into(),
            Fault::FlashWriteFail => "flash-write-fail".into(),
            Fault::FlashReadFail => "flash-read-fail".into(),
            Fault::ClearSpam => "clear-spam".into(),
            Fault::CorruptStartClear => "corrupt-start-clear".into(),
        }
    }
}

/// Small deterministic normal generator (SplitMix64 + Box–Muller), so a
/// noise fault is the same on every run.
#[derive(Debug, Clone)]
pub struct Gauss(u64);

impl Gauss {
    /// Seeded generator.
    pub fn new(seed: u64) -> Self {
        Gauss(seed)
    }

    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// One standard normal draw.
    pub fn normal(&mut self) -> f64 {
        let u1 = self.uniform().max(1e-300);
        let u2 = self.uniform();
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    }
}

/// Apply input fault `f` on channel `c` to a true sample, `dt_s` after the
/// fault started; `frozen` is the channel's value at the start.
pub fn corrupt_sample(s: &mut Sample, c: Channel, f: InputFault, dt_s: f64, frozen: f32, rng: &mut Gauss) {
    let v = c.get(s);
    let fs = c.full_scale();
    let out = match f {
        InputFault::StuckLast => frozen,
        InputFault::StuckZero => 0.0,
        InputFault::StuckFull => fs,
        InputFault::BiasUp => v + 0.2 * fs,
        InputFault::BiasDown => v - 0.2 * fs,
        InputFault::GainHalf => 0.5 * v,
        InputFault::GainOneAndHalf => 1.5 * v,
        InputFault::Drift => {
            let k = (dt_s / DRIFT_S).clamp(0.0, 1.0) as f32;
            if c == Channel::Ambient {
                v - 20.0 * k
            } else {
                v * (1.0 - k)
            }
        }
        InputFault::Noise => v + (0.05 * f64::from(fs) * rng.normal()) as f32,
        InputFault::NaN => f32::NAN,
        InputFault::OutOfRange => 1.5 * fs,
    };
    c.set(s, out);
}
