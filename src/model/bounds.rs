//! The parameter block's bounds table: every word of [`ModelConsts`] has a
//! physical range, written down here with its reason, checked when the
//! model is built (the compiled-in constants and every flashed block).
//!
//! **Adding a word** to [`ModelConsts`] (a temperature table, a margin):
//! add its line here, at its place in field order, with the range and the
//! reason, and bump the block's format version
//! ([`crate::params_block::VERSION`]). The unit test
//! `every_word_has_exactly_one_bound_in_field_order` fails until the line is
//! there (it reads the field order from `ModelConsts`'s `Debug` output), and
//! a compile-time assertion fails when the counts do not add up to
//! [`N_WORDS`].
//!
//! Units are the model's (docs/firmware.md): kW, kJ, L, L/s, hbar (100 bar),
//! hrad/s (100 rad/s), hA (100 A), °C, s. The ranges span EHAs from well
//! below to well above the paper rig (its values in the reasons); a lower
//! bound above zero marks a physical effect every real machine has (a pump
//! leaks, a winding has resistance, a motor has a torque constant): zero
//! there is a block that was not filled in, not a machine. What a range
//! cannot see is checked on the model itself ([`super::Model::check_physics`]:
//! it must heat, and cool at rest no faster than its bound says).

use super::consts::{ModelConsts, N_WORDS};
use super::ConfigError;
use crate::params::{N_COARSE, N_DUCTS, N_NODES, N_PHI, N_RE, N_TABLE, N_TEMP};

/// A range of one or more consecutive words.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bound {
    /// Words it covers (consecutive, in field order).
    pub n: u16,
    /// Smallest allowed value.
    pub lo: f32,
    /// Largest allowed value.
    pub hi: f32,
}

/// Declares the table: `field: n × [lo, hi] "reason"`, in field order. A
/// field may take several lines (per element ranges).
macro_rules! bounds {
    ($($field:ident : $n:expr, [$lo:expr, $hi:expr], $why:expr;)*) => {
        /// The ranges, in word order.
        pub const BOUNDS: [Bound; [$(stringify!($field)),*].len()] = [$(Bound { n: $n as u16, lo: $lo, hi: $hi }),*];
        /// The field of each range (host tools, docs).
        pub const FIELDS: [&str; BOUNDS.len()] = [$(stringify!($field)),*];
        /// Why each range is what it is (host tools, docs).
        pub const WHY: [&str; BOUNDS.len()] = [$($why),*];
    };
}

bounds! {
    p_case: 1, [0.0, 0.2], "case (drain) pressure 0-20 bar gauge (paper rig 5 bar)";
    k_lf: 1, [3.0e-5, 0.1], "pump leakage per port, L/s per 100 bar: every pump leaks, and the leakage carries the heat to the case (rig 3.4e-3)";
    k_lf_half: 1, [1.5e-5, 0.05], "half of k_lf (also checked as such)";
    k_lp: 1, [3.0e-4, 1.0], "leakage heat, kW per (100 bar)^2: 10 k_lf (checked)";
    k_mech: 1, [0.01, 50.0], "pump mechanical loss eta_m D, kW per (100 bar x 100 rad/s): eta_m 0.01-1 over 0.1-500 cm3/rev (rig 0.84)";
    k_q: 1, [1.6e-3, 8.0], "pump displacement, L/s per 100 rad/s: 0.1-500 cm3/rev (rig 0.30, 19 cm3/rev)";
    k_a: 1, [1.0e-3, 20.0], "piston area, L/s per mm/tick (rig 0.15)";
    k_dpq: 1, [10.0, 10.0], "unit constant 100 bar x L/s in kW: any other value is a wrong block";
    r1: 1, [0.0, 100.0], "line loss, laminar, kW per (L/s)^2 (rig 0.59)";
    r2: 1, [0.0, 100.0], "line loss, local, kW per (L/s)^3 (rig 1.0)";
    w_dp: 1, [0.0, 1.0], "actuator heat weight of dp^2, a share";
    w_dx: 1, [0.0, 1.0], "actuator heat weight of dx^2, a share";
    k_act: 1, [0.0, 10.0], "actuator heat scale, kW (rig 0.02)";
    k_cu: 1, [1.0e-3, 100.0], "copper loss phases R, kW per (100 A)^2: every winding has resistance (rig 2.2)";
    k_sh: 1, [0.05, 100.0], "shaft power per current, kW per (100 A x 100 rad/s): torque constant 0.005-10 N m/A (rig 7.5); 0 would switch the sensor cross-check off";
    k_hyd: 1, [0.016, 80.0], "hydraulic power of the displacement: 10 k_q (checked)";
    fe1: 1, [0.0, 10.0], "iron loss, hysteresis, kW per 100 rad/s (rig 0.037)";
    fe2: 1, [0.0, 10.0], "iron loss, eddy, kW per (100 rad/s)^2 (rig 0.016)";
    fe15: 1, [0.0, 10.0], "iron loss, excess, kW per (100 rad/s)^1.5 (rig 0.0084)";
    q_scale: 1, [1.0, 250.0], "flow table index scale 31/sqrt(q_max), tables up to 0.015-960 L/s (rig 22.5)";
    w_scale: 1, [1.0, 250.0], "speed table index scale 31/sqrt(w_max) (rig 12.4)";
    rc0: 1, [1.0, 2.5], "oil rho c_p at 0 degC, kJ/(L K): hydraulic oils 1.5-1.8 (rig 1.55)";
    rc1: 1, [0.0, 0.01], "slope of rho c_p, kJ/(L K^2): c_p rises with temperature (rig 0.0032)";
    rc2: 1, [-1.0e-4, 1.0e-4], "curvature of rho c_p, kJ/(L K^3): density and c_p each linear in T (rig -2.1e-6); rho c_p > 0 over -60..150 degC checked";
    inv_v_case: 1, [0.02, 200.0], "1 / case oil volume, 1/L: 5 mL to 50 L (rig 0.15 L)";
    inv_v_loop: 1, [2.0e-3, 200.0], "1 / loop oil volume, 1/L: 5 mL to 500 L (rig 1.43 L)";
    v_port: 1, [1.0e-3, 10.0], "one port passage's oil volume, L (rig 0.05)";
    v_ball: 1, [1.0e-3, 10.0], "ball-valve passage oil volume, L (rig 0.05)";
    inv_v_ring: 1, [1.0e-3, 200.0], "1 / ring oil volume, 1/L (rig 1.58 L)";
    f_out: 1, [0.0, 1.0], "share of the mechanical loss into the delivered oil (with f_case at most 1, checked)";
    f_case: 1, [0.0, 1.0], "share of the friction into the case oil";
    k_m0: 1, [0.0, 10.0], "no-load friction, kW per 100 rad/s (rig 0.03: 0.3 N m)";
    k_mv: 1, [0.0, 10.0], "viscous friction, kW per (100 rad/s)^2 (rig 0.06)";
    alpha: 1, [4.0e-4, 1.0e-3], "oil expansion coefficient, 1/K: mineral and synthetic hydraulic oils 6-8e-4";
    g_case_slope: 1, [-0.05, 0.05], "relative slope of the case film conductance, 1/K (rig -5.3e-4)";
    alpha_t0: 1, [0.109, 0.274], "alpha x 273.15 (checked)";
    lng_in: 1, [-200.0, -100.0], "LNG inlet temperature, degC (Table 6: -162)";
    pole_pairs: 1, [1.0, 50.0], "motor pole pairs (rig 4): the drive's electrical frequency is pole pairs x rev/s, the speed check's second source";
    drain_margin_k: 1, [0.0, 10.0], "commissioning margin added to the drain estimate, K (paper rig 0): negative would lower the estimate below the model (the cold side); above 10 K the valve would open at 30 degC and the model is not fit to protect the machine: recommission instead";
    inv_c: 1, [1.0e-4, 10.0], "1 / pump housing capacity, K/kJ: 0.1-10 000 kJ/K (rig 9.2 kJ/K)";
    inv_c: 2, [0.0, 0.0], "oil nodes: their capacity comes from rho c_p and the volume, this word must be 0";
    inv_c: 3, [1.0e-4, 10.0], "1 / capacity of the main block, ball-valve block and actuator, K/kJ";
    ga: 4, [0.0, 0.1], "outer surfaces, constant conductance, kW/K (eqs. 15-16)";
    gb: 4, [0.0, 0.1], "outer surfaces, |dT|^(1/4) conductance, kW/K^1.25";
    gr: 4, [0.0, 0.1], "outer surfaces, radiation 4 eps sigma A (300 K)^3, kW/K (eq. 19)";
    g_case: N_TABLE, [0.0, 1.0], "case oil - pump housing film over speed, kW/K (rig 0.9-3.2e-3)";
    g_port: N_TABLE, [0.0, 1.0], "port passage - pump housing over flow, kW/K (first point checked > 0)";
    g_loop: N_TABLE, [0.0, 1.0], "loop oil - main block over flow, kW/K";
    g_ball: N_TABLE, [0.0, 1.0], "ball-valve oil - its block over flow, kW/K (first point checked > 0)";
    g_lng: N_TABLE, [0.0, 1.0], "LNG exchanger eps C_min over flow, kW/K (eqs. 20-22)";
    leak_ratio: N_TEMP, [1.0e-4, 100.0], "leakage ratio mu(40)/mu(T) over -20..177.5 degC (VG 46 rig 0.0098-24.9; 1 at 40 degC and rising checked)";
    visc_ratio: N_TEMP, [1.0e-3, 250.0], "viscous friction ratio mu(T)/mu(40) (rig 102 at -20 degC to 0.040; 1 at 40 degC and falling checked)";
    tc_speed: N_TEMP, [1.0e-4, 100.0], "case-gap speed factor nu(40)/nu(T) (rig 0.010-22.6; 1 at 40 degC and rising checked)";
    re_q: N_DUCTS, [1.0e-3, 100.0], "duct Reynolds number / 1e4 per L/s at 40 degC: bores 2-50 mm (rig 0.23-0.35)";
    g_wall: 2, [1.0e-4, 10.0], "block walls behind the loop and ball-valve films, kW/K (rig 0.09, 0.02)";
    g_trans: N_COARSE * N_RE * N_DUCTS, [0.0, 100.0], "duct films at Re 2300/1e4/3e4/1e5 on the coarse temperature grid, kW/K (rig 7.9e-4 to 34)";
    rest_rate: N_NODES, [0.0, 1.0e-3], "cooling bound at rest, 1/s: time constants above 17 min (rig 5.4-20 h; checked against the model)";
    rest_mode: N_NODES, [0.0, 1.0], "cooling bound's mode shape, node order";
    phi: N_PHI * N_PHI, [-1.0e-4, 0.1], "exact-ZOH matrix Phi of the 0.1 s step over the pump housing, case oil and loop oil, s (diagonal near 0.1; checked against the model's own Jacobian)";
}

// const evaluation: an out-of-range index is a compile error, never a panic
#[allow(clippy::indexing_slicing)]
const _: () = {
    let mut n = 0;
    let mut i = 0;
    while i < BOUNDS.len() {
        n += BOUNDS[i].n as usize;
        i += 1;
    }
    assert!(n == N_WORDS, "the bounds table does not cover every word of ModelConsts");
};

/// Relative tolerance of the words derived from others (`k_lf_half`,
/// `k_lp`, `k_hyd`, `alpha_t0`): their f32 rounding.
const DERIVED_TOL: f32 = 1e-5;

impl<S: super::Word> ModelConsts<S> {
    /// Every word within its range of [`BOUNDS`] (the index of the first
    /// word that is not, in [`ConfigError::OutOfBounds`]), and the derived
    /// words equal to their derivation ([`ConfigError::Inconsistent`]).
    pub fn check_bounds(&self) -> Result<(), ConfigError> {
        let words = self.as_words();
        let mut at = 0usize;
        for b in BOUNDS.iter() {
            let n = usize::from(b.n);
            for (k, w) in words.get(at..at + n).unwrap_or(&[]).iter().enumerate() {
                let x = w.to_f32();
                // (a NaN fails)
                if !(b.lo..=b.hi).contains(&x) {
                    return Err(ConfigError::OutOfBounds(u16::try_from(at + k).unwrap_or(u16::MAX)));
                }
            }
            at += n;
        }
        let f = |x: S| x.to_f32();
        let same = |a: f32, b: f32| (a - b).abs() <= DERIVED_TOL * a.abs().max(b.abs());
        let ok = same(f(self.k_lf_half), 0.5 * f(self.k_lf))
            && same(f(self.k_lp), 10.0 * f(self.k_lf))
            && same(f(self.k_hyd), 10.0 * f(self.k_q))
            && same(f(self.alpha_t0), 273.15 * f(self.alpha));
        if ok {
            Ok(())
        } else {
            Err(ConfigError::Inconsistent)
        }
    }
}

/// The field, the index within it and the range of word `word` (host tools).
pub fn word_bound(word: usize) -> Option<(&'static str, usize, Bound, &'static str)> {
    let mut at = 0usize;
    let mut field_at = 0usize;
    let mut last = "";
    for ((b, name), why) in BOUNDS.iter().zip(FIELDS.iter()).zip(WHY.iter()) {
        if *name != last {
            field_at = at;
            last = name;
        }
        let n = usize::from(b.n);
        if word < at + n {
            return Some((name, word - field_at, *b, why));
        }
        at += n;
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    extern crate std;
    use std::string::String;
    use std::vec::Vec;

    /// The fields of `ModelConsts` in order with their word counts, read
    /// from its `Debug` output (every word printed as `0`).
    fn fields_in_order() -> Vec<(String, usize)> {
        let zero = crate::model::DEFAULT_CONSTS.map(|_| 0u8);
        let text = std::format!("{zero:?}");
        let body = text.trim_start_matches("ModelConsts {").trim_end_matches('}');
        let mut out: Vec<(String, usize)> = Vec::new();
        let ident = |t: &str| t.starts_with(|c: char| c.is_ascii_alphabetic()) && t.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        for part in body.split(": ") {
            // each part: "<words of the previous field>, <next field name>"
            // (the last: only words)
            let (words, name) = match part.rfind(", ") {
                Some(k) if ident(part[k + 2..].trim()) => (&part[..k], part[k + 2..].trim()),
                _ if ident(part.trim()) => ("", part.trim()),
                _ => (part, ""),
            };
            if let Some(last) = out.last_mut() {
                last.1 = words.matches('0').count();
            }
            if !name.is_empty() {
                out.push((name.into(), 0));
            }
        }
        out
    }

    #[test]
    fn every_word_has_exactly_one_bound_in_field_order() {
        let fields = fields_in_order();
        let mut table: Vec<(String, usize)> = Vec::new();
        for (b, name) in BOUNDS.iter().zip(FIELDS.iter()) {
            match table.last_mut() {
                Some(last) if last.0 == *name => last.1 += usize::from(b.n),
                _ => table.push((String::from(*name), usize::from(b.n))),
            }
        }
        assert_eq!(table, fields, "the bounds table (left) must list every field of ModelConsts (right) in order with its word count");
    }

    #[test]
    fn the_compiled_in_constants_are_within_their_bounds() {
        assert_eq!(crate::model::DEFAULT_CONSTS.check_bounds(), Ok(()));
    }

    #[test]
    fn an_out_of_range_word_is_named() {
        let c = ModelConsts { k_sh: 0.0, ..crate::model::DEFAULT_CONSTS };
        let Err(ConfigError::OutOfBounds(w)) = c.check_bounds() else { panic!("k_sh = 0 accepted") };
        assert_eq!(word_bound(usize::from(w)).map(|b| b.0), Some("k_sh"));
        let mut c = crate::model::DEFAULT_CONSTS;
        c.inv_c[2] = 0.1;
        let Err(ConfigError::OutOfBounds(w)) = c.check_bounds() else { panic!("an oil capacity word accepted") };
        assert_eq!(word_bound(usize::from(w)).map(|b| (b.0, b.1)), Some(("inv_c", 2)));
        let c = ModelConsts { k_lp: crate::model::DEFAULT_CONSTS.k_lp * 1.01, ..crate::model::DEFAULT_CONSTS };
        assert_eq!(c.check_bounds(), Err(ConfigError::Inconsistent));
    }
}
