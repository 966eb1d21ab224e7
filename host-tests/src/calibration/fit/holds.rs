//! Which calibration parameters the logs cannot move, decided before any
//! fit from what the logs carry and how they run: a missing sensor, one
//! operating point, the churned case film without a drain near rest and
//! at speed, the ducts' turbulent level without flow in the transition,
//! the caller's holds, the pump's structural freedoms without the loss
//! level from the current. The screening at the rig file
//! ([`super::calibrate`], step 2) holds more.

use super::CalOptions;
use crate::calibration::log::{self, CalLog};
use crate::calibration::set::{self, Needs, PARAMS};
use crate::calibration::ident;
use crate::rig::Rig;

/// Per parameter of [`PARAMS`], why it is held before the screening
/// (`None`: a candidate to fit).
pub(super) fn held_by_the_logs(base: &Rig, logs: &[CalLog], o: &CalOptions) -> Vec<Option<String>> {
    // 1. Which parameters have the sensor they need in at least one log.
    let mut held: Vec<Option<String>> = PARAMS
        .iter()
        .map(|d| match d.needs {
            Needs::Sensor(ch) if !logs.iter().any(|l| l.has(ch)) => {
                Some(format!("no log carries `{}`; would need: {}", ch.name(), d.excitation))
            }
            Needs::Input(ch) if !logs.iter().any(|l| log::input_above_zero(&l.run, ch)) => {
                Some(format!("no log has `{}` above 0; would need: {}", ch.name(), d.excitation))
            }
            Needs::SensorWithJointExcitation(ch)
                if !logs.iter().any(|l| l.has(ch) && ident::independent_speed_and_load(&l.run)) =>
            {
                Some(format!("no log with `{}` moves speed and load independently; would need: {}", ch.name(), d.excitation))
            }
            _ => None,
        })
        .collect();
    // 1b. One operating point in every log: losses that differ only in how
    // they scale with speed and pressure are a single constant heat there;
    // `pump_friction` stands for the pump's, the others are held.
    if ident::all_one_point(logs) {
        for name in ["leak_gap", "iron_loss", "winding_r", "needle_split"] {
            let k = set::index(name).expect("calibration parameter");
            held[k].get_or_insert_with(|| format!("every log has one operating point; would need: {}", PARAMS[k].excitation));
        }
    }
    // 1c. The churned case film needs the drain both near rest and at
    // speed: without, its level and the gap's floor trade freely.
    if !ident::case_film_speed_range(logs) {
        let (low, high) = ident::drain_time_low_and_high_speed_s(logs);
        for name in [set::CASE_CHURN, set::CASE_CHURN_SPEED] {
            let k = set::index(name).expect("calibration parameter");
            held[k].get_or_insert_with(|| {
                format!(
                    "the logs with `t_drain_c` spend {low:.0} s below {:.0} rpm and {high:.0} s above {:.0} rpm (needs {:.0} s of each); would need: {}",
                    ident::CASE_FILM_LOW_RPM,
                    ident::CASE_FILM_HIGH_RPM,
                    ident::CASE_FILM_MIN_S,
                    PARAMS[k].excitation
                )
            });
        }
    }
    // 1c'. The ducts' turbulent level needs the passages' flow in the
    // transition, hot: below Re 2300 it acts on nothing.
    if !ident::duct_transition_range(logs, base) {
        let (secs, top) = ident::duct_transition_time_s(logs, base);
        let k = set::index(set::DUCT_TURBULENT).expect("calibration parameter");
        held[k].get_or_insert_with(|| {
            format!(
                "the logs with the block and oil sensors spend {secs:.0} s with the main-block passage's flow above Re {:.0} (needs {:.0} s; highest Re {top:.0}); would need: {}",
                ident::DUCT_TRANSITION_RE,
                ident::DUCT_TRANSITION_MIN_S,
                PARAMS[k].excitation
            )
        });
    }
    for (name, why) in &o.hold {
        if let Some(k) = set::index(name) {
            held[k].get_or_insert_with(|| why.clone());
        }
    }
    // 1d. The pump's structural freedoms (where its friction heat goes, how
    // that friction scales with speed, where the surface probes read) only
    // beside a loss level that the temperatures do not fit as well
    // (`commission` takes `pump_friction` from the current): with the level
    // free, each trades with the pump housing's triad (h_out_pump,
    // film_case, pump_friction, whose common scale the temperatures pin only
    // to ~20 %). Measured with the level fitted: the recovery test (truth:
    // the rule, probes on their metal) fitted friction_case 1.13,
    // friction_speed 1.23 and moved the triad's ratio 0.16 in ln; the probes
    // alone fitted −1 … −4 % and moved cap_pump 0.84 -> 1.01 (truth 0.80);
    // the rig emulator's nominal machine (no drain) fitted its pump probe
    // 10.7 %, its block's 18.3 % (bound), held-out pooled RMSE 0.84 -> 0.95 K.
    let pf = set::index("pump_friction").expect("param");
    let structural = [set::FRICTION_CASE, set::FRICTION_SPEED].into_iter().chain(set::PROBE_SURFACE);
    for name in structural {
        let k = set::index(name).expect("param");
        if held[pf].is_none() {
            held[k].get_or_insert_with(|| "fitted only with the pump's loss level from the current (`pump_friction` held by `commission` when `current_a` is logged): with the level fitted from the temperatures too, it trades with the pump housing's heat paths".into());
        }
    }
    held
}
