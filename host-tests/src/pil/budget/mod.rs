//! Firmware resource budgets: `eha-sim fw-budget` runs the benchmark image
//! in QEMU under `-icount` (instruction counts, stack painting; see
//! `boards/mps2/src/bin/eha-bench/`), reads the flash and static RAM of every image
//! from its ELF, writes `out/fw-budget.json` and compares each figure with
//! the committed budgets (`.ci/fw-budget.json`): a figure more than
//! [`REGRESSION_MARGIN`] above its budget fails.
//!
//! Instruction counts under `-icount` are deterministic, so the margin is for
//! compiler and dependency updates, not for noise.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};

use super::firmware::{build_bin, workspace_root, Build, MPS2, STM32F4};

mod elf;
pub use elf::{elf_load_size, elf_sizes};

/// Allowed growth over a committed budget (fraction): 10 %.
pub const REGRESSION_MARGIN: f64 = 0.10;

/// The measured figures of one firmware image (`None`: not measured for it).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ImageBudget {
    /// `Guard::tick` instructions per 10 ms tick, mean over the bench run.
    pub instr_per_tick_mean: Option<f64>,
    /// `Guard::tick` instructions per tick, max (a model-step tick).
    pub instr_per_tick_max: Option<f64>,
    /// `Guard::new` instructions (init, once per boot).
    pub guard_new_instr: Option<f64>,
    /// Stack high-water mark of boot + init, bytes (stack painting).
    pub stack_boot_b: Option<f64>,
    /// Stack high-water mark of the tick loop, bytes.
    pub stack_tick_b: Option<f64>,
    /// Flash: `.text` + `.rodata`, bytes (the definition).
    pub flash_b: Option<f64>,
    /// Flash of the whole load image: vector table, `.text`, `.rodata` and the
    /// initial values of `.data`, bytes.
    #[serde(default)]
    pub flash_total_b: Option<f64>,
    /// The product loop (`App::tick`: frame in, guard, pins, record, reply)
    /// instructions per tick, mean (product image only).
    #[serde(default)]
    pub loop_instr_per_tick_mean: Option<f64>,
    /// The product loop's instructions per tick, max.
    #[serde(default)]
    pub loop_instr_per_tick_max: Option<f64>,
    /// Static RAM: every allocated writable section (`.data`, `.bss`, no-init), bytes.
    pub ram_static_b: Option<f64>,
}

impl ImageBudget {
    fn fields(&self) -> [(&'static str, Option<f64>); 10] {
        [
            ("instr_per_tick_mean", self.instr_per_tick_mean),
            ("instr_per_tick_max", self.instr_per_tick_max),
            ("guard_new_instr", self.guard_new_instr),
            ("stack_boot_b", self.stack_boot_b),
            ("stack_tick_b", self.stack_tick_b),
            ("flash_b", self.flash_b),
            ("flash_total_b", self.flash_total_b),
            ("ram_static_b", self.ram_static_b),
            ("loop_instr_per_tick_mean", self.loop_instr_per_tick_mean),
            ("loop_instr_per_tick_max", self.loop_instr_per_tick_max),
        ]
    }
}

/// One image the budget covers.
struct Image {
    name: &'static str,
    build: Build,
    /// The board crate and its binary.
    package: &'static str,
    bin: &'static str,
    features: &'static [&'static str],
    /// How the image is run in QEMU, if at all.
    run: Run,
}

/// How an image's run-time figures are measured.
#[derive(Clone, Copy, PartialEq)]
enum Run {
    /// Not run (flash and static RAM only).
    No,
    /// The bench image under `-icount`: instructions and stack.
    Bench,
    /// The product image over its UART in real time: boot and tick-loop stack
    /// from its status reply.
    Product,
}

const IMAGES: [Image; 4] = [
    Image { name: "bench-f32", build: Build::F32, package: MPS2, bin: "eha-bench", features: &[], run: Run::Bench },
    Image { name: "bench-fixed", build: Build::Fixed, package: MPS2, bin: "eha-bench", features: &[], run: Run::Bench },
    Image { name: "product-mps2", build: Build::F32, package: MPS2, bin: "eha-mps2", features: &["fault-inject"], run: Run::Product },
    Image { name: "stm32f411", build: Build::F32, package: STM32F4, bin: "eha-stm32f4", features: &[], run: Run::No },
];

/// Boot and tick-loop stack of the product image: 3 s of the drill's
/// samples (valid, faulty, lost) paced by its tick replies, then its status.
fn run_product(elf: &Path) -> Result<ImageBudget> {
    let mut s = super::product::ProductSession::spawn(elf, &[])?;
    let mut others = Vec::new();
    let mut open = false;
    for r in super::drill::requests().iter().take(300) {
        s.send(&super::drill::bytes(r, open))?;
        let (_, t) = s.next_tick(Duration::from_secs(2), &mut others)?.context("no tick reply from the product image")?;
        open = t.out.valve_open;
    }
    let st = s.status(1, &mut Vec::new())?;
    Ok(ImageBudget {
        stack_boot_b: Some(f64::from(st.boot_stack_b)),
        stack_tick_b: Some(f64::from(st.stack_high_water_b)),
        ..Default::default()
    })
}

/// The number after `key` in `line` (e.g. `mean 333.1`).
fn number_after(line: &str, key: &str) -> Option<f64> {
    let rest = &line[line.find(key)? + key.len()..];
    rest.split_whitespace().next()?.trim_end_matches(',').parse().ok()
}

/// Parse the bench's semihosting report into the run-time figures.
pub fn parse_bench(text: &str) -> Result<ImageBudget> {
    if !text.lines().any(|l| l.trim() == "EHA-BENCH-DONE") {
        bail!("the benchmark did not complete (no EHA-BENCH-DONE marker)");
    }
    let mut b = ImageBudget::default();
    for l in text.lines() {
        if l.starts_with("Guard::tick, every tick:") {
            b.instr_per_tick_mean = number_after(l, " mean ");
            b.instr_per_tick_max = number_after(l, " max ");
        } else if l.starts_with("Guard::new") {
            b.guard_new_instr = number_after(l, "): ");
        } else if l.starts_with("stack high-water mark:") {
            b.stack_boot_b = number_after(l, "boot+init ");
            b.stack_tick_b = number_after(l, "tick loop ");
        }
    }
    for (k, v) in b.fields() {
        let from_bench = ["instr_per_tick_mean", "instr_per_tick_max", "guard_new_instr", "stack_boot_b", "stack_tick_b"];
        if v.is_none() && from_bench.contains(&k) {
            bail!("the benchmark report has no {k}");
        }
    }
    Ok(b)
}

/// The product loop's cost per tick (`App::tick`, mean and max
/// instructions) from a bench report, if it has the line.
pub fn parse_app_tick(text: &str) -> Option<(f64, f64)> {
    let l = text.lines().find(|l| l.starts_with("App::tick"))?;
    Some((number_after(l, " mean ")?, number_after(l, " max ")?))
}

/// Run a bench ELF in QEMU under `-icount` and return its report (stderr).
fn run_bench(build: Build, elf: &Path) -> Result<String> {
    let mut child = Command::new("qemu-system-arm")
        .args(["-machine", build.machine(), "-cpu", build.cpu(), "-nographic", "-monitor", "none", "-serial", "none"])
        .args(["-semihosting-config", "enable=on,target=native", "-icount", "shift=10,align=off,sleep=off", "-kernel"])
        .arg(elf)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .context("starting qemu-system-arm (apt-get install qemu-system-arm)")?;
    let mut err = child.stderr.take().context("qemu stderr")?;
    let reader = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut err, &mut s);
        s
    });
    let deadline = std::time::Instant::now() + Duration::from_secs(120);
    let status = loop {
        if let Some(st) = child.try_wait()? {
            break st;
        }
        if std::time::Instant::now() > deadline {
            let _ = child.kill();
            bail!("the benchmark {} did not finish within 120 s", elf.display());
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let text = reader.join().unwrap_or_default();
    if !status.success() {
        bail!("the benchmark {} exited with {status}:\n{text}", elf.display());
    }
    Ok(text)
}

/// Measure every image (building it if needed).
pub fn measure() -> Result<BTreeMap<String, ImageBudget>> {
    let mut out = BTreeMap::new();
    // The product image's instructions per tick come from the f32 bench image
    // (same profile, same guard and application code, timed under -icount on
    // an in-memory board): `Guard::tick` (the estimator, as for the bench
    // images), `App::tick` (the whole loop) and `Guard::new`.
    let mut app_tick = None;
    let mut bench_f32 = ImageBudget::default();
    for im in &IMAGES {
        let elf = build_bin(im.build, im.package, im.bin, im.features)?;
        let mut b = match im.run {
            Run::Bench => {
                let text = run_bench(im.build, &elf)?;
                let b = parse_bench(&text)?;
                if im.build == Build::F32 {
                    app_tick = parse_app_tick(&text);
                    bench_f32 = b.clone();
                }
                b
            }
            Run::Product => {
                let mut b = run_product(&elf)?;
                let (mean, max) = app_tick.context("the f32 bench report has no App::tick line")?;
                (b.loop_instr_per_tick_mean, b.loop_instr_per_tick_max) = (Some(mean), Some(max));
                (b.instr_per_tick_mean, b.instr_per_tick_max) = (bench_f32.instr_per_tick_mean, bench_f32.instr_per_tick_max);
                b.guard_new_instr = bench_f32.guard_new_instr;
                b
            }
            Run::No => ImageBudget::default(),
        };
        let (flash, ram) = elf_sizes(&elf)?;
        b.flash_b = Some(flash as f64);
        b.flash_total_b = Some(elf_load_size(&elf)? as f64);
        b.ram_static_b = Some(ram as f64);
        out.insert(im.name.to_string(), b);
    }
    Ok(out)
}

/// Every figure more than [`REGRESSION_MARGIN`] over its budget, and every
/// budgeted figure that was not measured, as messages; empty: within budget.
pub fn regressions(measured: &BTreeMap<String, ImageBudget>, budget: &BTreeMap<String, ImageBudget>) -> Vec<String> {
    let mut v = Vec::new();
    for (name, want) in budget {
        let got = measured.get(name);
        for ((key, limit), (_, value)) in want.fields().into_iter().zip(got.cloned().unwrap_or_default().fields()) {
            let Some(limit) = limit else { continue };
            match value {
                None => v.push(format!("{name}.{key}: budgeted {limit} but not measured")),
                Some(x) if x > limit * (1.0 + REGRESSION_MARGIN) => v.push(format!(
                    "{name}.{key}: {x} > budget {limit} + {:.0} %",
                    100.0 * REGRESSION_MARGIN
                )),
                Some(_) => {}
            }
        }
    }
    v
}

/// The product image's absolute budgets: `Guard::tick` ≤ 400 instructions
/// per tick on the mean, `Guard::new` ≤ 100 k, boot stack ≤ 4 KiB, tick-loop
/// stack ≤ 2 KiB, flash (`.text` + `.rodata`) ≤ 40 KiB (32 KiB before the
/// safety case and the oil's tables over temperature; what each feature
/// costs is in docs/firmware-numbers.md), the whole product loop
/// (`App::tick`: frame in, guard, pins, record, reply) ≤ 1 500 instructions
/// per tick on the mean.
pub const PRODUCT_LIMITS: [(&str, f64); 6] = [
    ("instr_per_tick_mean", 400.0),
    ("guard_new_instr", 100_000.0),
    ("stack_boot_b", 4096.0),
    ("stack_tick_b", 2048.0),
    ("flash_b", 40960.0),
    ("loop_instr_per_tick_mean", 1500.0),
];

/// Every [`PRODUCT_LIMITS`] figure of `product-mps2` that is over its limit
/// or missing, as messages.
pub fn over_product_limits(measured: &BTreeMap<String, ImageBudget>) -> Vec<String> {
    let got = measured.get("product-mps2").cloned().unwrap_or_default();
    let fields = got.fields();
    PRODUCT_LIMITS
        .iter()
        .filter_map(|(key, limit)| {
            let value = fields.iter().find(|(k, _)| k == key).and_then(|(_, v)| *v);
            match value {
                Some(x) if x <= *limit => None,
                Some(x) => Some(format!("product-mps2.{key}: {x} > the product limit {limit}")),
                None => Some(format!("product-mps2.{key}: not measured (product limit {limit})")),
            }
        })
        .collect()
}

/// What each figure is, for the rendered table.
const FIELD_LABELS: [(&str, &str); 10] = [
    ("instr_per_tick_mean", "`Guard::tick` instructions per 10 ms tick, mean (QEMU -icount)"),
    ("instr_per_tick_max", "`Guard::tick` instructions, max (a model-step tick)"),
    ("guard_new_instr", "`Guard::new` instructions (boot: block, bounds, checks, stability)"),
    ("stack_boot_b", "stack high-water, boot + init, B (stack painting)"),
    ("stack_tick_b", "stack high-water, tick loop, B"),
    ("flash_b", "flash `.text` + `.rodata`, B"),
    ("flash_total_b", "flash, whole load image, B"),
    ("ram_static_b", "static RAM (`.data`, `.bss`, no-init), B"),
    ("loop_instr_per_tick_mean", "product loop (`App::tick`) instructions per tick, mean"),
    ("loop_instr_per_tick_max", "product loop instructions per tick, max"),
];

/// Every image's figures as a Markdown table (rows: figures, columns:
/// images; `–` where an image does not measure a figure).
pub fn markdown(budgets: &BTreeMap<String, ImageBudget>) -> String {
    let mut s = String::from("| figure |");
    for name in budgets.keys() {
        s.push_str(&format!(" {name} |"));
    }
    s.push_str("\n|---|");
    s.push_str(&"---:|".repeat(budgets.len()));
    s.push('\n');
    for (k, (key, label)) in FIELD_LABELS.iter().enumerate() {
        s.push_str(&format!("| {label} |"));
        for b in budgets.values() {
            let (f, v) = b.fields()[k];
            debug_assert_eq!(f, *key);
            match v {
                Some(x) if x.fract() == 0.0 => s.push_str(&format!(" {x:.0} |")),
                Some(x) => s.push_str(&format!(" {x:.1} |")),
                None => s.push_str(" – |"),
            }
        }
        s.push('\n');
    }
    s
}

/// Arguments of `eha-sim fw-budget`.
#[derive(Debug, Clone, clap::Args)]
pub struct BudgetArgs {
    /// Where to write the measured figures.
    #[arg(long, default_value = "out/fw-budget.json")]
    pub out: PathBuf,
    /// The committed budgets to check against (relative to the workspace root).
    #[arg(long, default_value = ".ci/fw-budget.json")]
    pub budget: PathBuf,
}

/// `eha-sim fw-budget`: measure, write, compare; an error lists every regression.
pub fn run(a: &BudgetArgs) -> Result<()> {
    let measured = measure()?;
    if let Some(dir) = a.out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    let json = serde_json::to_string_pretty(&measured)?;
    std::fs::write(&a.out, &json).with_context(|| format!("writing {}", a.out.display()))?;
    println!("{json}");
    println!("wrote {}", a.out.display());
    let path = if a.budget.is_absolute() { a.budget.clone() } else { workspace_root().join(&a.budget) };
    let text = std::fs::read_to_string(&path).with_context(|| format!("reading the budgets {}", path.display()))?;
    let budget: BTreeMap<String, ImageBudget> =
        serde_json::from_str(&text).with_context(|| format!("parsing the budgets {}", path.display()))?;
    let mut r = over_product_limits(&measured);
    r.extend(regressions(&measured, &budget));
    if !r.is_empty() {
        bail!("firmware budget exceeded ({}):\n  {}", path.display(), r.join("\n  "));
    }
    println!(
        "every figure within {} + {:.0} %, and the product image within its limits (400 instr/tick, 100 k init, 4/2 KiB stack, 40 KiB flash)",
        path.display(),
        100.0 * REGRESSION_MARGIN
    );
    Ok(())
}

#[cfg(test)]
mod tests;
