//! The emulator sweep's summary tables: answers by imprint-ratio band (r
//! against each log's effect-free twin) and the reliability of the stated
//! probabilities (stated probability against observed frequency).

use super::emu_result::{EmuResult, TwinCheck};
use super::model::Candidate;
use super::report::ProbabilityJson;
use std::fmt::Write as _;

/// One diagnosed log of the sweep: a case log or an effect-free twin.
#[derive(Debug, Clone)]
pub struct Diagnosed<'a> {
    /// Seed of the case.
    pub seed: u64,
    /// Whether this is the effect-free twin of a case.
    pub twin: bool,
    /// The hidden effect in this log (`none` for twins and effect-free cases).
    pub truth: &'static str,
    /// Imprint ratio of the case's effect (`None` for effect-free logs).
    pub ratio: Option<f64>,
    /// The answer.
    pub answer: &'a str,
    /// Its posterior.
    pub probabilities: &'a [ProbabilityJson],
}

/// An answer and its posterior.
type Answer<'a> = (&'a str, &'a [ProbabilityJson]);

/// Every log of `ok` that `case` (a case log) or `twin` (its effect-free
/// twin) gives an answer for, the twins after their cases.
fn diagnosed_by<'a>(
    ok: &'a [EmuResult],
    case: impl Fn(&'a EmuResult) -> Option<Answer<'a>>,
    twin: impl Fn(&'a TwinCheck) -> Option<Answer<'a>>,
) -> Vec<Diagnosed<'a>> {
    let mut out = Vec::new();
    for r in ok {
        let ratio = r.twin.as_ref().map(|t| t.ratio());
        if let Some((answer, probabilities)) = case(r) {
            out.push(Diagnosed { seed: r.case.seed, twin: false, truth: r.case.hidden.name(), ratio, answer, probabilities });
        }
        if let Some((answer, probabilities)) = r.twin.as_ref().and_then(&twin) {
            out.push(Diagnosed { seed: r.case.seed, twin: true, truth: Candidate::None.name(), ratio: None, answer, probabilities });
        }
    }
    out
}

/// Every diagnosed log of `ok`, the twins after their cases.
pub fn diagnosed(ok: &[EmuResult]) -> Vec<Diagnosed<'_>> {
    diagnosed_by(ok, |r| Some((&r.answer, &r.probabilities)), |t| Some((&t.twin_answer, &t.twin_probabilities)))
}

/// Every log of `ok` with a posterior under the measured rule
/// ([`EmuResult::measured`]), its answer and probabilities under it.
pub fn diagnosed_measured(ok: &[EmuResult]) -> Vec<Diagnosed<'_>> {
    diagnosed_by(
        ok,
        |r| r.measured.as_ref().map(|m| (m.answer.as_str(), m.probabilities.as_slice())),
        |t| t.twin_measured.as_ref().map(|m| (m.answer.as_str(), m.probabilities.as_slice())),
    )
}

/// Seeds of the original case set (seeds 1700 + 100·k + index, k < 10):
/// the half on which a measured rule's constants are chosen.
pub fn in_fit_half(seed: u64) -> bool {
    seed < 2700
}

/// The measured rule's section: its counts (named and right at r ≥ 2,
/// wrong causes, false discoveries) and reliability tables pooled, on the
/// half its constants were chosen on and on the other. Empty when no
/// result carries it.
pub fn measured_rule_section(ok: &[EmuResult]) -> String {
    let all = diagnosed_measured(ok);
    let Some(rule) = ok.iter().find_map(|r| r.measured.as_ref().map(|m| m.rule.clone())) else { return String::new() };
    let names = |d: &&Diagnosed| super::evidence::names_a_cause(d.answer);
    let must: Vec<&Diagnosed> = all.iter().filter(|d| d.truth != "none" && d.ratio.is_some_and(|r| r >= 2.0)).collect();
    let wrong: Vec<String> = all
        .iter()
        .filter(|d| d.truth != "none" && names(d) && d.answer != d.truth)
        .map(|d| format!("{}: `{}`", d.seed, d.answer))
        .collect();
    let fd: Vec<String> =
        all.iter().filter(|d| d.truth == "none" && names(d)).map(|d| format!("{}{}: `{}`", d.seed, if d.twin { "'s twin" } else { "" }, d.answer)).collect();
    let mut md = format!(
        "\n**Under the `{rule}` rule** (decided again from the stored evidence terms of {} logs, `emulator-sweep --measure {rule}`): named at r ≥ 2: {} of {} ({} right); wrong causes: {}{}; false discoveries: {} of {} effect-free{}.\n",
        all.len(),
        must.iter().filter(|d| names(d)).count(),
        must.len(),
        must.iter().filter(|d| d.answer == d.truth).count(),
        wrong.len(),
        if wrong.is_empty() { String::new() } else { format!(" ({})", wrong.join(", ")) },
        fd.len(),
        all.iter().filter(|d| d.truth == "none").count(),
        if fd.is_empty() { String::new() } else { format!(" ({})", fd.join(", ")) },
    );
    let fit: Vec<Diagnosed> = all.iter().filter(|d| in_fit_half(d.seed)).cloned().collect();
    let judge: Vec<Diagnosed> = all.iter().filter(|d| !in_fit_half(d.seed)).cloned().collect();
    for (label, set) in [
        ("all logs", &all),
        ("the original case set (seeds 1700–1717), where the rule's constants were chosen", &fit),
        ("the identification-run set (seeds 2700–2711), not used to choose them", &judge),
    ] {
        if set.is_empty() {
            continue;
        }
        let _ = write!(md, "\nReliability under `{rule}`, {label} ({} logs):\n", set.len());
        md += &bins_markdown(&reliability_of(set));
    }
    md
}

/// The answers on logs with a hidden effect by imprint-ratio band (named,
/// right, wrong cause, `none`, `unexplained`), and on the effect-free logs
/// (the case set's and the twins) the false discoveries. Empty without
/// twins.
pub fn ratio_table(ok: &[EmuResult]) -> String {
    let all = diagnosed(ok);
    let with: Vec<(&Diagnosed, f64)> = all.iter().filter_map(|d| Some((d, d.ratio?))).filter(|(d, _)| d.truth != "none").collect();
    if with.is_empty() {
        return String::new();
    }
    let mut md = String::from(
        "\n**By imprint ratio** r = the calibrated baseline's held-out misfit on the affected channel over the same on the \
         log's effect-free twin (same machine, mission and noise); a cause must be named at r ≥ 2, a wrong cause is wrong at any r:\n\n\
         | r | logs | named | right | wrong cause | `none` | `unexplained` | seeds (r) |\n|---|---:|---:|---:|---:|---:|---:|---|\n",
    );
    for (label, lo, hi) in [("< 1", 0.0, 1.0), ("1–2", 1.0, 2.0), ("2–3", 2.0, 3.0), ("≥ 3", 3.0, f64::INFINITY)] {
        let band: Vec<&(&Diagnosed, f64)> = with.iter().filter(|(_, r)| *r >= lo && *r < hi).collect();
        let n = |f: &dyn Fn(&Diagnosed) -> bool| band.iter().filter(|(d, _)| f(d)).count();
        let seeds: Vec<String> = band
            .iter()
            .map(|(d, x)| {
                let mark = if d.answer == d.truth { "✓" } else if super::evidence::names_a_cause(d.answer) { "✗" } else { "" };
                format!("{}{mark} ({x:.1})", d.seed)
            })
            .collect();
        let _ = writeln!(
            md,
            "| {label} | {} | {} | {} | {} | {} | {} | {} |",
            band.len(),
            n(&|d| super::evidence::names_a_cause(d.answer)),
            n(&|d| d.answer == d.truth),
            n(&|d| super::evidence::names_a_cause(d.answer) && d.answer != d.truth),
            n(&|d| d.answer == "none"),
            n(&|d| d.answer == "unexplained"),
            if seeds.is_empty() { "–".into() } else { seeds.join(", ") },
        );
    }
    let free: Vec<&Diagnosed> = all.iter().filter(|d| d.truth == "none").collect();
    let wrong: Vec<String> =
        free.iter().filter(|d| super::evidence::names_a_cause(d.answer)).map(|d| format!("{}{}: `{}`", d.seed, if d.twin { "'s twin" } else { "" }, d.answer)).collect();
    let _ = writeln!(
        md,
        "\nEffect-free logs ({} of the case sets, {} twins): {} `none`, {} `unexplained`, **{} false discoveries**{}.",
        free.iter().filter(|d| !d.twin).count(),
        free.iter().filter(|d| d.twin).count(),
        free.iter().filter(|d| d.answer == "none").count(),
        free.iter().filter(|d| d.answer == "unexplained").count(),
        wrong.len(),
        if wrong.is_empty() { String::new() } else { format!(" ({})", wrong.join(", ")) }
    );
    md
}

/// The statements a report makes about one log, on the posterior with
/// `none` and `unexplained` merged into "no cause" (the emulator knows
/// only whether an effect is hidden, not which of the two a foreign
/// machine deserves): the named cause when one reaches the naming
/// probability, else the two most probable. (statement, probability).
pub fn statements(probabilities: &[ProbabilityJson]) -> Vec<(String, f64)> {
    let mut merged: Vec<(String, f64)> = vec![("no cause".into(), 0.0)];
    for p in probabilities {
        if super::evidence::names_a_cause(&p.cause) {
            merged.push((p.cause.clone(), p.probability));
        } else {
            merged[0].1 += p.probability;
        }
    }
    merged.sort_by(|a, b| b.1.total_cmp(&a.1));
    let named = merged[0].0 != "no cause" && merged[0].1 >= super::evidence::NAME_PROBABILITY;
    merged.truncate(if named { 1 } else { 2 });
    merged
}

/// Probability bins of the reliability table.
pub const BINS: [(f64, f64); 7] = [(0.0, 0.1), (0.1, 0.3), (0.3, 0.5), (0.5, 0.7), (0.7, 0.9), (0.9, 0.99), (0.99, 1.0 + 1e-9)];

/// One bin of the reliability table.
#[derive(Debug, Clone, PartialEq)]
pub struct Bin {
    /// Bin bounds.
    pub range: (f64, f64),
    /// Statements in the bin.
    pub n: usize,
    /// Mean stated probability.
    pub stated: f64,
    /// Fraction of the statements that are true, the truth being the hidden
    /// effect at any r ("no cause" on an effect-free log).
    pub observed: f64,
    /// Fraction true with the truth the answers are judged by: the hidden
    /// effect when it stands clear of the floor (r ≥ 2), else "no cause".
    /// One truth per log, so a log's statements' probabilities and their
    /// truths add up alike: below r = 2 "no cause" is true and the effect's
    /// own statement false.
    pub observed_at_floor: f64,
}

/// The reliability bins over every diagnosed log of `ok`.
pub fn reliability(ok: &[EmuResult]) -> Vec<Bin> {
    reliability_of(&diagnosed(ok))
}

/// The reliability bins over the logs `logs`.
pub fn reliability_of(logs: &[Diagnosed]) -> Vec<Bin> {
    let mut st: Vec<(f64, bool, bool)> = Vec::new();
    for d in logs {
        let truth = if d.truth == "none" { "no cause" } else { d.truth };
        let faint = d.ratio.is_some_and(|r| r < 2.0);
        let at_floor = if faint { "no cause" } else { truth };
        for (s, p) in statements(d.probabilities) {
            st.push((p, s == truth, s == at_floor));
        }
    }
    BINS.iter()
        .map(|&(lo, hi)| {
            let b: Vec<&(f64, bool, bool)> = st.iter().filter(|(p, ..)| *p >= lo && *p < hi).collect();
            let n = b.len();
            let mean = |f: &dyn Fn(&(f64, bool, bool)) -> f64| if n == 0 { f64::NAN } else { b.iter().map(|x| f(x)).sum::<f64>() / n as f64 };
            Bin {
                range: (lo, hi.min(1.0)),
                n,
                stated: mean(&|x| x.0),
                observed: mean(&|x| f64::from(u8::from(x.1))),
                observed_at_floor: mean(&|x| f64::from(u8::from(x.2))),
            }
        })
        .collect()
}

/// The reliability table in Markdown (empty when no log carries
/// probabilities).
pub fn reliability_table(ok: &[EmuResult]) -> String {
    let bins = reliability(ok);
    if bins.iter().all(|b| b.n == 0) {
        return String::new();
    }
    let mut md = String::from(
        "\n**Reliability of the stated probabilities** over every diagnosed log (case logs and twins): each report's \
         statements — the named cause, or else the two most probable, with `none` and `unexplained` merged into \
         \"no cause\" — binned by stated probability; observed = the fraction that is true (the hidden effect at any \
         r; \"no cause\" on an effect-free log), and the same with the truth the answers are judged by (the hidden \
         effect at r ≥ 2, else \"no cause\"). Calibrated: within 10 points in every bin with ≥ 5 statements.\n",
    );
    md += &bins_markdown(&bins);
    md
}

/// The reliability bins as a Markdown table; "within 10 points" judged on
/// the strict observed column and on the one with the answers' truth
/// (the effect at r ≥ 2, else "no cause").
pub fn bins_markdown(bins: &[Bin]) -> String {
    let mut md = String::from(
        "\n| stated P | statements | mean stated | observed | observed, truth at the floor (the effect at r ≥ 2, else no cause) | within 10 points (strict / at the floor) |\n|---|---:|---:|---:|---:|---|\n",
    );
    for b in bins {
        let pct = |x: f64| if x.is_nan() { "–".to_string() } else { format!("{:.0} %", 100.0 * x) };
        let within = |o: f64| if (b.stated - o).abs() <= 0.1 { "yes" } else { "**no**" };
        let ok = if b.n < 5 { "(< 5)".to_string() } else { format!("{} / {}", within(b.observed), within(b.observed_at_floor)) };
        let _ = writeln!(
            md,
            "| {:.2}–{:.2} | {} | {} | {} | {} | {ok} |",
            b.range.0,
            b.range.1,
            b.n,
            pct(b.stated),
            pct(b.observed),
            pct(b.observed_at_floor)
        );
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(c: &str, x: f64) -> ProbabilityJson {
        ProbabilityJson { cause: c.into(), probability: x, log_bayes_factor: 0.0, prior: 0.25, heldout_touched: None, heldout_untouched: None, identifiable: None }
    }

    /// A named cause is one statement; otherwise the two most probable,
    /// with `none` and `unexplained` summed into "no cause".
    #[test]
    fn statements_merge_no_cause_and_keep_the_top_two() {
        let s = statements(&[p("sensor-lag", 0.95), p("none", 0.03), p("unexplained", 0.02)]);
        assert_eq!(s, vec![("sensor-lag".to_string(), 0.95)]);
        let s = statements(&[p("none", 0.95), p("unexplained", 0.04), p("churning-loss", 0.01)]);
        assert_eq!((s.len(), s[0].0.as_str(), s[1].0.as_str()), (2, "no cause", "churning-loss"), "a `none` report states its top two");
        assert!((s[0].1 - 0.99).abs() < 1e-12);
        let s = statements(&[p("sensor-lag", 0.5), p("none", 0.3), p("unexplained", 0.15), p("churning-loss", 0.05)]);
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].0, "sensor-lag");
        assert_eq!(s[1].0, "no cause");
        assert!((s[1].1 - 0.45).abs() < 1e-12);
    }
}
