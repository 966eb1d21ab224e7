//! modelDescription.xml (FMI 2.0, co-simulation) from a model's variable
//! table, and the FMU archive around it.

use crate::fmi2::{Causality, Model, Var, VarType};
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

/// The SI base-unit expression of each unit symbol the models use.
const UNITS: [(&str, &str); 14] = [
    ("1", ""),
    ("A", r#"A="1""#),
    ("J", r#"kg="1" m="2" s="-2""#),
    ("K", r#"K="1""#),
    ("W", r#"kg="1" m="2" s="-3""#),
    ("bar", r#"kg="1" m="-1" s="-2" factor="100000""#),
    ("degC", r#"K="1" offset="273.15""#),
    ("kg", r#"kg="1""#),
    ("l/min", r#"m="3" s="-1" factor="1.6666666666666667e-05""#),
    ("m/s", r#"m="1" s="-1""#),
    ("mm", r#"m="1" factor="0.001""#),
    ("mm/s", r#"m="1" s="-1" factor="0.001""#),
    ("rpm", r#"rad="1" s="-1" factor="0.10471975511965977""#),
    ("s", r#"s="1""#),
];

/// XML text escaping for attribute values.
fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Shortest round-trip decimal of an f64 (Rust's `{:?}` is exact).
fn num(x: f64) -> String {
    format!("{x:?}")
}

/// The modelDescription.xml of model `M`, with a default experiment of
/// `stop_s` in steps of `step_s`.
pub fn model_description<M: Model>(stop_s: f64, step_s: f64) -> Result<String, String> {
    let vars = M::variables();
    let mut used: Vec<&str> = vars
        .iter()
        .filter_map(|v| match v.ty {
            VarType::Real { unit, .. } => Some(unit),
            _ => None,
        })
        .collect();
    used.sort_unstable();
    used.dedup();
    let mut x = String::new();
    let w = &mut x;
    let _ = writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        w,
        r#"<fmiModelDescription fmiVersion="2.0" modelName="{id}" guid="{guid}" description="{d}" generationTool="eha-fmu {ver}" variableNamingConvention="flat" numberOfEventIndicators="0">"#,
        id = M::IDENTIFIER,
        guid = M::GUID,
        d = esc(M::DESCRIPTION),
        ver = env!("CARGO_PKG_VERSION"),
    );
    let _ = writeln!(
        w,
        r#"  <CoSimulation modelIdentifier="{}" canHandleVariableCommunicationStepSize="true" canInterpolateInputs="false" maxOutputDerivativeOrder="0" canRunAsynchronuously="false" canBeInstantiatedOnlyOncePerProcess="false" canNotUseMemoryManagementFunctions="true" canGetAndSetFMUstate="false" canSerializeFMUstate="false" providesDirectionalDerivative="false"/>"#,
        M::IDENTIFIER
    );
    let _ = writeln!(w, "  <UnitDefinitions>");
    for u in &used {
        let base = UNITS.iter().find(|(n, _)| n == u).ok_or_else(|| format!("unit {u:?} has no SI definition in description.rs"))?.1;
        if base.is_empty() {
            let _ = writeln!(w, r#"    <Unit name="{}"/>"#, esc(u));
        } else {
            let _ = writeln!(w, r#"    <Unit name="{}"><BaseUnit {base}/></Unit>"#, esc(u));
        }
    }
    let _ = writeln!(w, "  </UnitDefinitions>");
    let _ = writeln!(w, r#"  <DefaultExperiment startTime="0.0" stopTime="{}" stepSize="{}"/>"#, num(stop_s), num(step_s));
    let _ = writeln!(w, "  <ModelVariables>");
    let mut outputs = Vec::new();
    for (i, v) in vars.iter().enumerate() {
        var_xml(w, v);
        if v.causality == Causality::Output {
            outputs.push(i + 1);
        }
    }
    let _ = writeln!(w, "  </ModelVariables>");
    let _ = writeln!(w, "  <ModelStructure>");
    let _ = writeln!(w, "    <Outputs>");
    for i in &outputs {
        let _ = writeln!(w, r#"      <Unknown index="{i}"/>"#);
    }
    let _ = writeln!(w, "    </Outputs>");
    let _ = writeln!(w, "    <InitialUnknowns>");
    for i in &outputs {
        let _ = writeln!(w, r#"      <Unknown index="{i}"/>"#);
    }
    let _ = writeln!(w, "    </InitialUnknowns>");
    let _ = writeln!(w, "  </ModelStructure>");
    let _ = writeln!(w, "</fmiModelDescription>");
    Ok(x)
}

fn var_xml(w: &mut String, v: &Var) {
    let (causality, variability, initial) = match (v.causality, v.ty) {
        (Causality::Parameter, _) => ("parameter", "fixed", ""),
        (Causality::Input, VarType::Real { .. }) => ("input", "continuous", ""),
        (Causality::Input, _) => ("input", "discrete", ""),
        (Causality::Output, VarType::Real { .. }) => ("output", "continuous", r#" initial="calculated""#),
        (Causality::Output, _) => ("output", "discrete", r#" initial="calculated""#),
    };
    let _ = writeln!(
        w,
        r#"    <ScalarVariable name="{}" valueReference="{}" causality="{causality}" variability="{variability}"{initial} description="{}">"#,
        esc(v.name),
        v.vr,
        esc(v.description)
    );
    let ty = match v.ty {
        VarType::Real { unit, start } => {
            let s = start.map(|s| format!(r#" start="{}""#, num(s))).unwrap_or_default();
            format!(r#"<Real unit="{}"{s}/>"#, esc(unit))
        }
        VarType::Integer { start } => format!("<Integer{}/>", start.map(|s| format!(r#" start="{s}""#)).unwrap_or_default()),
        VarType::Boolean { start } => format!("<Boolean{}/>", start.map(|s| format!(r#" start="{s}""#)).unwrap_or_default()),
        VarType::String { start } => format!(r#"<String start="{}"/>"#, esc(start)),
    };
    let _ = writeln!(w, "      {ty}");
    let _ = writeln!(w, "    </ScalarVariable>");
}

/// Writes `dir/<modelIdentifier>.fmu`: the description and the shared
/// library `lib` as `binaries/linux64/<modelIdentifier>.so`.
pub fn write_fmu<M: Model>(dir: &Path, lib: &Path, stop_s: f64, step_s: f64) -> anyhow::Result<std::path::PathBuf> {
    use anyhow::Context;
    let xml = model_description::<M>(stop_s, step_s).map_err(anyhow::Error::msg)?;
    let so = std::fs::read(lib).with_context(|| format!("reading the FMU library {}", lib.display()))?;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let path = dir.join(format!("{}.fmu", M::IDENTIFIER));
    let f = std::fs::File::create(&path).with_context(|| format!("creating {}", path.display()))?;
    let mut z = zip::ZipWriter::new(f);
    let opt = zip::write::SimpleFileOptions::default().compression_method(zip::CompressionMethod::Deflated);
    z.start_file("modelDescription.xml", opt)?;
    z.write_all(xml.as_bytes())?;
    z.add_directory("binaries/", opt)?;
    z.add_directory("binaries/linux64/", opt)?;
    z.start_file(format!("binaries/linux64/{}.so", M::IDENTIFIER), opt.unix_permissions(0o755))?;
    z.write_all(&so)?;
    z.finish()?;
    Ok(path)
}
