//! The candidate model extensions the diagnosis tries and the rig emulator
//! can hide (the rig file's `[ext]` section, `crate::rig::Extensions`), and
//! the realistic magnitude of each. Below the simulation so that every
//! generator of logs and the diagnosis share one list.

/// A candidate model extension (the rig file's `[ext]` section); `None` is
/// the baseline. Names are the strings `diagnosis.json` reports. `viscosity-temperature`
/// is retired: the oil's viscosity follows its Walther line in the baseline
/// of the reference and of the emulator, so there is nothing left to find.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Candidate {
    /// Copper resistance rising with winding temperature, R = R0(1+α(T−T0)) (eq. 1).
    WindingResistanceTemperature,
    /// Manifold oil sensor in a dead-end pocket, first-order lag (paper Figs. 9–10).
    SensorLag,
    /// Non-linear (Coulomb) actuator friction (paper Case 2).
    CoulombFriction,
    /// Pump churning loss ∝ ω^2.5 (eq. 8 mechanical-loss term).
    ChurningLoss,
    /// Direct conduction between motor and pump housings (Point 2 joint).
    MotorPumpConduction,
    /// Unlogged forced convection over the housings (eqs. 17–19, Table 5).
    ForcedConvection,
    /// No extension: the baseline.
    None,
}

impl Candidate {
    /// The extensions tried by the diagnosis, in report order.
    pub const EXTENSIONS: [Candidate; 6] = [
        Candidate::WindingResistanceTemperature,
        Candidate::SensorLag,
        Candidate::CoulombFriction,
        Candidate::ChurningLoss,
        Candidate::MotorPumpConduction,
        Candidate::ForcedConvection,
    ];

    /// Exact name used in reports, JSON and tests.
    pub fn name(self) -> &'static str {
        match self {
            Candidate::WindingResistanceTemperature => "winding-resistance-temperature",
            Candidate::SensorLag => "sensor-lag",
            Candidate::CoulombFriction => "coulomb-friction",
            Candidate::ChurningLoss => "churning-loss",
            Candidate::MotorPumpConduction => "motor-pump-conduction",
            Candidate::ForcedConvection => "forced-convection",
            Candidate::None => "none",
        }
    }

    /// The candidate with exact name `s`.
    pub fn from_name(s: &str) -> Option<Candidate> {
        Candidate::EXTENSIONS.into_iter().chain([Candidate::None]).find(|c| c.name() == s)
    }
}

impl std::fmt::Display for Candidate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Realistic magnitude range of each extension (its parameter's unit in
/// `eha_sim::rig::Extensions`).
pub fn magnitude_range(c: Candidate) -> (f64, f64) {
    match c {
        // copper: 3.9e-3 1/K; alloys and winding hot spots 3e-3…4.3e-3
        Candidate::WindingResistanceTemperature => (3.0e-3, 4.3e-3),
        // dead-end pocket (Figs. 9–10): minutes
        Candidate::SensorLag => (60.0, 240.0),
        // piston-seal Coulomb friction of a 1527 mm² ram, N (2–4 % of
        // its 30 kN force at 200 bar)
        Candidate::CoulombFriction => (500.0, 1200.0),
        // churning ∝ ω^2.5, 60–150 W at 1500 rpm (ω^2.5 ≈ 3.2e5)
        Candidate::ChurningLoss => (2.0e-4, 5.0e-4),
        // flange conduction, W/K
        Candidate::MotorPumpConduction => (3.0, 8.0),
        // unlogged fan / draught, m/s (Table 5 ram air is 15–50 m/s)
        Candidate::ForcedConvection => (5.0, 12.0),
        Candidate::None => (1.0, 1.0),
    }
}
