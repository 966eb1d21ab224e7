//! The emulator case sets: each candidate in two operating families
//! ([`default_cases`]) or in identification runs ([`ident_cases`]), seeded
//! so that a case keeps its seed when others leave ([`RETIRED`]).
//! Separate because it is the sweep's inputs, not its diagnosis.

use crate::diagnosis::model::Candidate;
use crate::emulator::missions::EmuScenario;
use crate::emulator::{generate, generate_twin, EmuCase};
use crate::measured::MeasuredRun;

/// The default case set: two scenarios per candidate (each chosen to excite
/// it) and four without a hidden effect; seeds `base + k`. The two
/// `viscosity-temperature` slots are retired (the viscosity is part of the
/// baseline now) and left out, keeping every other case on its seed.
pub fn default_cases(duration_s: f64, base: u64) -> Vec<EmuCase> {
    use EmuScenario::*;
    let list: [(&str, EmuScenario); 18] = [
        ("winding-resistance-temperature", PressureSpeedSteps),
        ("winding-resistance-temperature", LoadCycles),
        ("viscosity-temperature", LoadCycles),
        ("viscosity-temperature", PressureSpeedSteps),
        ("sensor-lag", ConstantThrottle),
        ("sensor-lag", SpeedSteps),
        ("coulomb-friction", ServoHoldMove),
        ("coulomb-friction", ServoHoldMove),
        ("churning-loss", SpeedSteps),
        ("churning-loss", PressureSpeedSteps),
        ("motor-pump-conduction", ConstantThrottle),
        ("motor-pump-conduction", LoadCycles),
        ("forced-convection", ConstantThrottle),
        ("forced-convection", AirSteps),
        ("none", ConstantThrottle),
        ("none", LoadCycles),
        ("none", SpeedSteps),
        ("none", ServoHoldMove),
    ];
    cases_from(&list, duration_s, base)
}

/// The identification-run case set: every throttle-circuit candidate hidden
/// in two [`EmuScenario::IdentRun`] logs (speed, load and ram air stepped
/// independently), Coulomb friction in two servo logs (only piston motion
/// shows it), and four logs with nothing hidden (three identification
/// runs, one servo run); seeds `base + index` (the retired
/// `viscosity-temperature` slots left out, as in [`default_cases`]).
pub fn ident_cases(duration_s: f64, base: u64) -> Vec<EmuCase> {
    use EmuScenario::*;
    let list: [(&str, EmuScenario); 18] = [
        ("winding-resistance-temperature", IdentRun),
        ("winding-resistance-temperature", IdentRun),
        ("viscosity-temperature", IdentRun),
        ("viscosity-temperature", IdentRun),
        ("sensor-lag", IdentRun),
        ("sensor-lag", IdentRun),
        ("coulomb-friction", ServoHoldMove),
        ("coulomb-friction", ServoHoldMove),
        ("churning-loss", IdentRun),
        ("churning-loss", IdentRun),
        ("motor-pump-conduction", IdentRun),
        ("motor-pump-conduction", IdentRun),
        ("forced-convection", IdentRun),
        ("forced-convection", IdentRun),
        ("none", IdentRun),
        ("none", IdentRun),
        ("none", IdentRun),
        ("none", ServoHoldMove),
    ];
    cases_from(&list, duration_s, base)
}

/// The cases of `list` (hidden candidate name, scenario), seeds `base + index`;
/// a retired candidate's slot ([`RETIRED`]) is skipped with its seed.
fn cases_from(list: &[(&str, EmuScenario)], duration_s: f64, base: u64) -> Vec<EmuCase> {
    list.iter()
        .enumerate()
        .filter(|(_, (h, _))| !RETIRED.contains(h))
        .map(|(k, (h, s))| EmuCase {
            hidden: Candidate::from_name(h).unwrap_or(Candidate::None),
            scenario: *s,
            seed: base + k as u64,
            duration_s,
        })
        .collect()
}

/// The case of `seed` in the first four repetitions of both case sets at
/// `duration_s` (seeds 1700–1717 … 2000–2017 of [`default_cases`],
/// 2700–2717 … 3000–3017 of [`ident_cases`]: what `emulator-sweep --cases
/// original,ident --seeds 4` runs); `None` for another seed or a retired
/// slot.
pub fn case_of_seed(duration_s: f64, seed: u64) -> Option<EmuCase> {
    // The repetition whose hundred holds `seed`, then the slot within it.
    let holds = |base: &u64| (*base..*base + 100).contains(&seed);
    let set = if let Some(b) = [1700, 1800, 1900, 2000].into_iter().find(holds) {
        default_cases(duration_s, b)
    } else if let Some(b) = [2700, 2800, 2900, 3000].into_iter().find(holds) {
        ident_cases(duration_s, b)
    } else {
        return None;
    };
    set.into_iter().find(|c| c.seed == seed)
}

/// The effect-free log of case `c` as the sweep diagnoses it: the case's
/// own log when nothing is hidden, else its twin (same machine, mission
/// and noise, without the effect).
pub fn effect_free_log(c: &EmuCase) -> Result<MeasuredRun, String> {
    if c.hidden == Candidate::None { generate(c) } else { generate_twin(c) }.map(|(run, _)| run)
}

/// Candidates that left the list (their effect is part of the baseline now):
/// their slots in the case sets keep their seeds unused.
pub const RETIRED: [&str; 1] = ["viscosity-temperature"];

#[cfg(test)]
mod tests {
    use super::*;

    /// Each repetition's seeds find their own set's case (the scenario and
    /// hidden effect of the same slot, the seed itself); retired slots and
    /// seeds outside the four repetitions find none.
    #[test]
    fn case_of_seed_finds_four_repetitions_of_both_sets() {
        for (base, set) in [(1700, default_cases(1200.0, 1700)), (2700, ident_cases(1200.0, 2700))] {
            for c in &set {
                for rep in 0..4 {
                    let found = case_of_seed(1200.0, c.seed + 100 * rep).expect("a case of the repetition");
                    assert_eq!((found.seed, found.scenario, found.hidden), (c.seed + 100 * rep, c.scenario, c.hidden), "set {base}");
                }
            }
        }
        assert!(case_of_seed(1200.0, 1702).is_none(), "a retired slot");
        assert!(case_of_seed(1200.0, 2100).is_none() && case_of_seed(1200.0, 1699).is_none() && case_of_seed(1200.0, 3100).is_none());
    }
}
