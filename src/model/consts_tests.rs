//! Tests of the model constants against the compiled-in ones (a module of
//! its own: the constants' module stays below `default_consts`, which uses it).

use super::consts::{derive, ModelConsts, N_WORDS};
use super::{ConfigError, DEFAULT_CONSTS};
use crate::params::DEFAULT;
extern crate std;

/// `src/model/default_consts.rs` is `derive(&DEFAULT)` rounded to f32, bit for bit
/// (regenerate with `cargo run --release -p eha-sim --example reduce -- --consts-only`).
#[test]
fn default_consts_are_derived_from_default() {
    let d = derive(&DEFAULT).unwrap().to_f32();
    let (mut a, mut b) = (std::vec::Vec::new(), std::vec::Vec::new());
    d.for_each(|x| a.push(x.to_bits()));
    DEFAULT_CONSTS.for_each(|x| b.push(x.to_bits()));
    assert_eq!(a.len(), N_WORDS);
    assert_eq!(a, b);
}

/// Words round-trip in order through `for_each` / `from_words`.
#[test]
fn words_round_trip() {
    let mut w = std::vec::Vec::new();
    DEFAULT_CONSTS.for_each(|x| w.push(x));
    let mut it = w.iter();
    let back = ModelConsts::from_words(|| it.next().copied().unwrap_or(f32::NAN));
    assert_eq!(back, DEFAULT_CONSTS);
}

/// Implausible words are refused by the value check.
#[test]
fn bad_words_are_refused() {
    let mut c = DEFAULT_CONSTS;
    c.g_case[3] = -0.1;
    assert_eq!(c.check_values(), Err(ConfigError::Implausible));
    let mut c = DEFAULT_CONSTS;
    c.k_mech = f32::NAN;
    assert_eq!(c.check_values(), Err(ConfigError::ConstantRange));
    let mut c = DEFAULT_CONSTS;
    c.rc1 = 300.0;
    assert_eq!(c.check_values(), Err(ConfigError::ConstantRange));
    // the new words' bounds: a temperature table not referred to 40 degC or
    // not monotonic, shares over 1
    let mut c = DEFAULT_CONSTS;
    c.leak_ratio = c.leak_ratio.map(|x| x * 1.01);
    assert_eq!(c.check_values(), Err(ConfigError::Implausible));
    let mut c = DEFAULT_CONSTS;
    c.visc_ratio.swap(0, 1);
    assert_eq!(c.check_values(), Err(ConfigError::Implausible));
    let mut c = DEFAULT_CONSTS;
    c.f_out = 0.9;
    assert_eq!(c.check_values(), Err(ConfigError::Implausible));
    // an Euler state with a capacity so small against its conductance that its
    // step would overshoot (the actuator at 1/20 of its capacity: its tidal
    // exchange at 1 m/s piston speed then gives h G / C = 0.9)
    let mut c = DEFAULT_CONSTS;
    c.inv_c[crate::params::NODE_ACTUATOR] *= 20.0;
    assert_eq!(c.check_values(), Err(ConfigError::Implausible));
    assert_eq!(DEFAULT_CONSTS.check_values(), Ok(()));
}
