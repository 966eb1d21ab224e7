//! The strict measured-data reader: every rejection rule of
//! `docs/measured-data-format.md` and a lossless write/read round trip.

use eha_sim::measured::{Channel, MeasuredError, MeasuredRun};

const HEADER: &str = "time_s,speed_rpm,current_a,p_a_bar,p_b_bar,ambient_c,t_oil_c";

fn file(rows: &[&str]) -> String {
    let mut s = String::from("# rig: bench-A\n# case: 1\n# free text without key\n");
    s.push_str(HEADER);
    s.push('\n');
    for r in rows {
        s.push_str(r);
        s.push('\n');
    }
    s
}

fn err(text: &str) -> MeasuredError {
    MeasuredRun::from_str_named("rig.csv", text).expect_err("file must be rejected")
}

#[test]
fn reads_metadata_missing_cells_and_ignores_unknown_columns() {
    let text = "# rig: bench-A\n# ambient_c: 16\n# a note without a key\n\
                time_s,speed_rpm,current_a,p_a_bar,p_b_bar,ambient_c,vendor_x,t_oil_c\n\
                0.0,500,12.5,60,1,16,abc,20.0\n\
                0.5,500,,60,1,16,, \n\
                1.0,-500,12.5,60,1,16,x,20.25\n";
    let run = MeasuredRun::from_str_named("rig.csv", text).unwrap();
    assert_eq!(run.meta("rig"), Some("bench-A"));
    assert_eq!(run.meta("ambient_c"), Some("16"));
    assert_eq!(run.metadata[2].key, "");
    assert_eq!(run.time_s, vec![0.0, 0.5, 1.0]);
    assert_eq!(run.get(Channel::CurrentA).unwrap(), &[Some(12.5), None, Some(12.5)]);
    assert_eq!(run.get(Channel::TOilC).unwrap(), &[Some(20.0), None, Some(20.25)]);
    assert_eq!(run.get(Channel::SpeedRpm).unwrap()[2], Some(-500.0));
    assert!(run.get(Channel::TPumpC).is_none());
    assert_eq!(run.notes.len(), 1, "{:?}", run.notes);
    assert!(run.notes[0].contains("vendor_x"));
    // Driving a model between samples interpolates over the gap, the stored
    // data keeps the gap.
    assert_eq!(run.value_at(Channel::TOilC, 0.5), Some(20.125));
}

#[test]
fn rejects_missing_required_column_naming_it() {
    for col in ["time_s", "speed_rpm", "current_a", "p_a_bar", "p_b_bar", "ambient_c"] {
        let hdr: Vec<&str> = HEADER.split(',').filter(|c| *c != col).collect();
        let row: Vec<&str> = hdr.iter().map(|_| "1").collect();
        let text = format!("{}\n{}\n", hdr.join(","), row.join(","));
        match err(&text) {
            MeasuredError::MissingColumn { file, line, column } => {
                assert_eq!((file.as_str(), line, column.as_str()), ("rig.csv", 1, col));
            }
            e => panic!("{col}: wrong error {e}"),
        }
    }
}

#[test]
fn rejects_time_not_strictly_increasing() {
    for bad in ["0.5", "0.4"] {
        let row3 = format!("{bad},500,10,60,1,16,20");
        let e = err(&file(&["0,500,10,60,1,16,20", "0.5,500,10,60,1,16,20", &row3]));
        let msg = e.to_string();
        assert!(matches!(e, MeasuredError::TimeNotIncreasing { line: 7, .. }), "{msg}");
        assert!(msg.contains("rig.csv:7") && msg.contains("time_s"), "{msg}");
    }
    let e = err(&file(&["0,500,10,60,1,16,20", ",500,10,60,1,16,20"]));
    assert!(matches!(e, MeasuredError::MissingTime { line: 6, .. }), "{e}");
}

#[test]
fn rejects_unparsable_value_with_line_and_column() {
    let e = err(&file(&["0,500,10,60,1,16,20", "1,500,10,6O,1,16,20"]));
    match &e {
        MeasuredError::Unparsable { file, line, column, value } => {
            assert_eq!((file.as_str(), *line, column.as_str(), value.as_str()), ("rig.csv", 6, "p_a_bar", "6O"));
        }
        e => panic!("wrong error {e}"),
    }
    assert!(e.to_string().contains("expected a decimal number"));
}

#[test]
fn rejects_non_finite_values_as_invalid_not_missing() {
    for bad in ["NaN", "nan", "inf", "-inf", "infinity"] {
        let row = format!("1,500,10,60,1,16,{bad}");
        match err(&file(&["0,500,10,60,1,16,20", &row])) {
            MeasuredError::NonFinite { line, column, .. } => assert_eq!((line, column.as_str()), (6, "t_oil_c")),
            e => panic!("{bad}: wrong error {e}"),
        }
    }
}

#[test]
fn rejects_out_of_range_values_without_clamping() {
    let cases = [
        ("1,500,10,60,1,16,250.5", "t_oil_c"),
        ("1,500,10,60,1,-60.1,20", "ambient_c"),
        ("1,500,10,700.01,1,16,20", "p_a_bar"),
        ("1,500,10,60,-1.5,16,20", "p_b_bar"),
        ("1,20001,10,60,1,16,20", "speed_rpm"),
        ("1,-20001,10,60,1,16,20", "speed_rpm"),
        ("1,500,-0.1,60,1,16,20", "current_a"),
        ("1,500,2000.5,60,1,16,20", "current_a"),
    ];
    for (row, col) in cases {
        match err(&file(&["0,500,10,60,1,16,20", row])) {
            MeasuredError::OutOfRange { line, column, .. } => assert_eq!((line, column.as_str()), (6, col), "{row}"),
            e => panic!("{row}: wrong error {e}"),
        }
    }
    // The bounds themselves are physical and accepted.
    let ok = file(&["0,20000,0,-1,700,-60,250", "1,-20000,2000,700,-1,250,-60"]);
    assert!(MeasuredRun::from_str_named("rig.csv", &ok).is_ok());
}

#[test]
fn rejects_malformed_rows_and_duplicate_columns() {
    let e = err(&file(&["0,500,10,60,1,16,20", "1,500,10,60,1,16"]));
    assert!(matches!(e, MeasuredError::Csv { line: 6, .. }), "{e}");
    let e = err("time_s,speed_rpm,current_a,p_a_bar,p_b_bar,ambient_c,speed_rpm\n0,1,1,1,1,1,1\n");
    assert!(matches!(e, MeasuredError::DuplicateColumn { line: 1, .. }), "{e}");
    assert!(matches!(err("# only metadata\n"), MeasuredError::NoHeader { .. }));
}

#[test]
fn round_trip_is_lossless() {
    let mut run = MeasuredRun::new(vec![0.0, 0.1, 0.30000000000000004, 1.5, 1e3]);
    run.push_meta("rig", "bench-A");
    run.push_meta("note", "x: y, with comma");
    run.push_meta("", "free text line");
    for (k, ch) in Channel::ALL.into_iter().enumerate() {
        let base = if ch == Channel::LngValve { 0.0 } else { 1.0 + k as f64 / 7.0 };
        let vals = (0..5).map(|i| if (i + k) % 4 == 3 { None } else { Some(base + i as f64 * 0.1) });
        let vals: Vec<Option<f64>> = vals.map(|v| v.map(|x| if ch == Channel::LngValve { x.min(1.0) } else { x })).collect();
        run.set(ch, vals);
    }
    let mut buf = Vec::new();
    run.write(&mut buf).unwrap();
    let text = String::from_utf8(buf).unwrap();
    let back = MeasuredRun::from_str_named("rt.csv", &text).unwrap();
    assert_eq!(back, run, "{text}");
    // The writer refuses what the reader would refuse.
    let mut bad = run.clone();
    bad.channels.get_mut(&Channel::TOilC).unwrap()[0] = Some(f64::NAN);
    assert!(bad.write(Vec::new()).is_err());
}

/// The optional bench column `t_drain_c`: read as
/// `Channel::TDrainC`, range-checked like every temperature (−60…250 °C,
/// error naming file, line and column) and written back in the format's
/// column order.
#[test]
fn reads_and_writes_optional_drain_column() {
    let text = "time_s,speed_rpm,current_a,p_a_bar,p_b_bar,ambient_c,t_oil_c,t_drain_c\n\
                0.0,500,12.5,60,1,16,20.0,21.5\n\
                1.0,500,12.5,60,1,16,20.1,\n";
    let run = MeasuredRun::from_str_named("bench.csv", text).expect("drain column accepted");
    assert_eq!(run.get(Channel::TDrainC).expect("drain"), &[Some(21.5), None]);
    assert!(run.notes.is_empty(), "not an unknown column: {:?}", run.notes);
    let mut out = Vec::new();
    run.write(&mut out).expect("write");
    let back = MeasuredRun::from_str_named("back.csv", std::str::from_utf8(&out).expect("utf8")).expect("read back");
    assert_eq!(back.get(Channel::TDrainC), run.get(Channel::TDrainC));
    let bad = text.replace("21.5", "300");
    let e = MeasuredRun::from_str_named("bench.csv", &bad).expect_err("out of range");
    let msg = e.to_string();
    assert!(msg.contains("bench.csv:2") && msg.contains("t_drain_c"), "{msg}");
}
