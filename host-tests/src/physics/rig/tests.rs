use super::*;

#[test]
fn toml_round_trip_and_override() {
    let rig = Rig::default();
    let back = Rig::from_toml_str(&rig.to_toml(), "rt").expect("round trip");
    assert_eq!(rig, back);
    let mut r = rig.clone();
    r.set_override("pump.gaps.piston_gap_m=10e-6").expect("override");
    assert_eq!(r.pump.gaps.piston_gap_m, 10e-6);
    r.set_override("ext.sensor_lag=60").expect("ext");
    assert_eq!(r.ext.sensor_lag, Some(60.0));
    r.set_override("ext.sensor_lag=none").expect("clear");
    assert_eq!(r.ext.sensor_lag, None);
    assert!(r.set_override("pump.nope=1").is_err());
    assert!(r.set_override("pump.eta_m").is_err());
    assert!(r.set_override("motor.r25_ohm=-1").is_err());
}

/// The a-priori metal paths of the pump (docs/calibration.md) by hand:
/// seats 1/(0.014/(45·6.1e-3) + 1/(5000·6.1e-3)) = 11.93 W/K, motor
/// flange 1/(0.06/(48·2.8e-3) + 1/(2000·7.5e-3)) = 1.949 W/K, manifold
/// 1/(0.05/(48·2.8e-3) + 1/(2000·4e-3)) = 2.012 W/K (to 1e-3 W/K).
#[test]
fn pump_metal_paths_by_hand() {
    let (s, j) = (PumpSplit::a_priori(), Joints::a_priori());
    let g = |w: &WallPath| w.conductance_w_per_k();
    for (got, want) in [(g(&s.seats), 11.93), (g(&j.pump_motor), 1.949), (g(&j.pump_manifold), 2.012)] {
        assert!((got - want).abs() < 1e-3 * want.max(1.0) + 5e-3, "{got} vs {want}");
    }
}

/// Keys that changed meaning are refused with a message, not ignored.
#[test]
fn removed_keys_are_refused() {
    let text = Rig::default().to_toml();
    let old = text.replace("[ext]", "[ext]\nviscosity_temperature = false");
    let e = Rig::from_toml_str(&old, "old").expect_err("refused");
    assert!(e.to_string().contains("Walther"), "{e}");
    let old = text.replace("emissivity = 0.85", "emissivity = 0.85\nram_property_c = 16.0");
    let e = Rig::from_toml_str(&old, "old").expect_err("refused");
    assert!(e.to_string().contains("altitude"), "{e}");
}

/// Every uncertain key names a number of the rig file, every range holds its
/// nominal and cites a source; a bad range is refused.
#[test]
fn uncertain_keys_resolve() {
    let rig = Rig::default();
    let doc = toml::Value::try_from(&rig).expect("toml");
    assert!(rig.uncertain.len() >= 15);
    for u in &rig.uncertain {
        for k in &u.keys {
            let v = k.split('.').try_fold(&doc, |d, p| d.get(p)).unwrap_or_else(|| panic!("{}: no key {k}", u.name));
            assert!(v.as_float().is_some_and(|x| x > 0.0), "{}: {k} is not a positive number", u.name);
        }
    }
    let mut bad = rig.clone();
    bad.uncertain[0].low = 1.2;
    assert!(Rig::from_toml_str(&bad.to_toml(), "bad").is_err());
}

/// The optional pump structure survives the TOML round trip and is off
/// by default.
#[test]
fn pump_as_built_round_trip() {
    assert!(Rig::default().pump.split.is_none() && Rig::default().joints.is_none());
    let rig = Rig::default().with_pump_as_built();
    let back = Rig::from_toml_str(&rig.to_toml(), "rt").expect("round trip");
    assert_eq!(rig, back);
    let mut r = rig.clone();
    r.set_override("pump.split=none").expect("clear");
    assert!(r.pump.split.is_none());
}
