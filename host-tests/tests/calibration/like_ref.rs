//! The experiment switches of the structural bisection: each makes the
//! emulator machine (or the user's rig file) like the reference in one
//! respect (docs/commissioning-foreign.md, "The held-out drain misses: structural
//! bisection"). Experiment knobs only; the product path reads none of them.

use eha_sim::emulator::bench::EmuMachine;
use eha_sim::rig::Rig;

/// The emulator machine with the experiment's changes (environment).
pub(super) fn variant(m: &mut EmuMachine) {
    if std::env::var("EXP_MECH_RULE").is_ok() {
        m.params.mech_split = [0.6, 0.15, 0.25];
    }
    let env = |k: &str| std::env::var(k).ok().and_then(|v| v.parse::<f64>().ok());
    if let Some(g) = env("EXP_G_BARREL_END") {
        m.params.g_barrel_end = g;
    }
    if let Some(f) = env("EXP_PROBE_AMBIENT") {
        m.params.probe_ambient_frac = f;
    }
    if let Some(w) = env("EXP_PROBE_BARREL") {
        m.params.pump_probe_barrel = w;
    }
    if let Some(k) = env("EXP_A_CASE") {
        m.params.a_case.iter_mut().for_each(|a| *a *= k);
    }
    if let Some(k) = env("EXP_GAP") {
        m.params.gap_m *= k;
    }
    like_reference(&mut m.params, &like_ref());
}

/// Every structural switch of the bisection (`EXP_LIKE_REF=all`).
pub(super) const ALL_SWITCHES: [&str; 10] = ["split", "onepump", "surface", "oilprobe", "drain", "flange", "blocks", "emiss", "gapfilm", "nofric"];

/// The structural switches of `EXP_LIKE_REF` (comma-separated; `all`: every one).
pub(super) fn like_ref() -> Vec<String> {
    parse_switches(&std::env::var("EXP_LIKE_REF").unwrap_or_default())
}

/// A comma-separated switch list (`all` in it: [`ALL_SWITCHES`], so
/// `all,ports` is the control and one more).
pub(super) fn parse_switches(v: &str) -> Vec<String> {
    v.split(',')
        .filter(|s| !s.is_empty())
        .flat_map(|s| if s == "all" { ALL_SWITCHES.map(String::from).to_vec() } else { vec![s.to_string()] })
        .collect()
}

/// Structural bisection: each named switch makes the emulator machine like
/// the reference in one respect (docs/commissioning-foreign.md, "The held-out drain
/// misses: structural bisection"): `split` the mechanical loss placed by the
/// reference's sliding-pair rule (delivered oil 0.6, case 0.15, metal 0.25);
/// `onepump` barrel and end cap one node (9 → 2000 W/K); `surface` the
/// surface probes read their metal (4 % towards ambient → 0) within 0.5 s
/// (8–14 s); `oilprobe` the oil probe's 2 s of the rig file; `drain` the
/// drain thermocouple within 0.5 s (3–5 s); `flange` no end cap → manifold
/// joint (the reference's pump housing has no metal path); `blocks` the
/// manifold plate part of the main block (500 W/K) and no ball → main block
/// joint; `emiss` the rig file's emissivity 0.85; `gapfilm` the case film
/// by the reference's gap law (`RefLaw::CaseGapFilm`);
/// `filmomeganu` the rotating cylinder's film as a function of ω/ν
/// (`RefLaw::CaseFilmOmegaNu`); `nodrag` no iron-loss drag in
/// the motor current (`RefLaw::NoIronDrag`); beyond the control's ten
/// (`all`): `ports` the port oil as two nodes (`RefLaw::TwoPorts`), `duct`
/// the duct films by the reference's law (`RefLaw::DuctLaw`; `ductblocks`
/// the block films' only, `RefLaw::DuctLawBlocks`), `wall` the
/// reference's block wall behind the block films (`RefLaw::BlockWall`),
/// `outer` the reference's outer-surface correlations (`RefLaw::OuterLaw`),
/// `mount` the main block's 2 W/K bench mount (`RefLaw::Mount`), `boost`
/// the rig file's 5 bar boost (the reference's case pressure, 4 bar in the
/// machine); `nofric` and
/// `nowall` act on the
/// rig file ([`rig_like_reference`]).
pub(super) fn like_reference(p: &mut eha_sim::emulator::params::EmuParams, switches: &[String]) {
    use eha_sim::emulator::params::RefLaw;
    for s in switches {
        match s.as_str() {
            "split" => p.mech_split = [0.6, 0.15, 0.25],
            "onepump" => p.g_barrel_end = 2000.0,
            "surface" => {
                p.probe_ambient_frac = 0.0;
                p.sensor_tau[..4].iter_mut().for_each(|t| *t = 0.5);
            }
            "oilprobe" => p.sensor_tau[4] = 2.0,
            "drain" => p.drain_tau_s = 0.5,
            "flange" => p.g_end_manifold = 0.0,
            "blocks" => {
                p.g_manifold_block = 500.0;
                p.g_ball_block = 0.0;
            }
            "emiss" => p.emissivity = 0.85,
            "boost" => p.boost_pa = 5e5,
            "gapfilm" => p.like_reference = p.like_reference.with(RefLaw::CaseGapFilm),
            "filmomeganu" => p.like_reference = p.like_reference.with(RefLaw::CaseFilmOmegaNu),
            "nodrag" => p.like_reference = p.like_reference.with(RefLaw::NoIronDrag),
            "ports" => p.like_reference = p.like_reference.with(RefLaw::TwoPorts),
            "duct" => p.like_reference = p.like_reference.with(RefLaw::DuctLaw),
            "ductblocks" => p.like_reference = p.like_reference.with(RefLaw::DuctLawBlocks),
            "wall" => p.like_reference = p.like_reference.with(RefLaw::BlockWall),
            "outer" => p.like_reference = p.like_reference.with(RefLaw::OuterLaw),
            "mount" => p.like_reference = p.like_reference.with(RefLaw::Mount),
            "nofric" | "nowall" => {}
            other => panic!("unknown structural switch `{other}`"),
        }
    }
}

/// The user's rig file with the experiment's changes: `nofric` takes the
/// no-load and viscous friction torques out (×1e-3; the emulator's
/// mechanical loss is the η_m term alone); `nowall` the blocks' wall behind
/// the loop and ball-valve films (`blocks.wall_m` ×0.1, `block_wall` then reaches ×1000; the emulator's
/// films have none in series).
pub(super) fn rig_like_reference(r: &mut Rig, switches: &[String]) {
    if switches.iter().any(|s| s == "nofric") {
        r.pump.no_load_torque_nm *= 1e-3;
        r.pump.viscous_torque_coeff *= 1e-3;
    }
    if switches.iter().any(|s| s == "nowall") {
        r.blocks.wall_m *= 0.1;
    }
}
