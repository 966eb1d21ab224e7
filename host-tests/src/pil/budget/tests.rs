//! The bench report's parser and the budget comparison on known texts.

use super::*;

#[test]
fn parses_the_bench_report() {
    let text = "Guard::tick, every tick: instructions/tick min 243 mean 333.1 max 1157 (n = 5995)\n\
                Guard::new (constants, checks, stability): 3920773 instructions\n\
                stack high-water mark: boot+init 13576 bytes, tick loop 6288 bytes\nEHA-BENCH-DONE\n";
    let b = parse_bench(text).expect("parses");
    assert_eq!(b.instr_per_tick_mean, Some(333.1));
    assert_eq!(b.instr_per_tick_max, Some(1157.0));
    assert_eq!(b.guard_new_instr, Some(3920773.0));
    assert_eq!((b.stack_boot_b, b.stack_tick_b), (Some(13576.0), Some(6288.0)));
    assert!(parse_bench("Guard::new (constants, checks, stability): 1 instructions\n").is_err(), "no completion marker");
}

#[test]
fn flags_only_growth_beyond_the_margin() {
    let b = |x: f64| ImageBudget { instr_per_tick_mean: Some(x), ..Default::default() };
    let budget = BTreeMap::from([("a".to_string(), b(100.0))]);
    assert!(regressions(&BTreeMap::from([("a".to_string(), b(110.0))]), &budget).is_empty());
    assert_eq!(regressions(&BTreeMap::from([("a".to_string(), b(110.5))]), &budget).len(), 1);
    assert_eq!(regressions(&BTreeMap::new(), &budget).len(), 1, "a budgeted image that was not measured fails");
}

/// The product image's absolute limits: the committed figures pass, one
/// byte over 40 KiB of flash fails, a loop over 1 500 instructions per
/// tick fails, a missing figure fails.
#[test]
fn product_limits_are_absolute() {
    let ok = ImageBudget {
        instr_per_tick_mean: Some(355.9),
        guard_new_instr: Some(61_765.0),
        stack_boot_b: Some(3056.0),
        stack_tick_b: Some(1240.0),
        flash_b: Some(31_132.0),
        loop_instr_per_tick_mean: Some(1476.9),
        ..Default::default()
    };
    let m = |b: ImageBudget| BTreeMap::from([("product-mps2".to_string(), b)]);
    assert!(over_product_limits(&m(ok.clone())).is_empty());
    assert_eq!(over_product_limits(&m(ImageBudget { flash_b: Some(40_961.0), ..ok.clone() })).len(), 1);
    assert_eq!(over_product_limits(&m(ImageBudget { loop_instr_per_tick_mean: Some(1500.1), ..ok.clone() })).len(), 1);
    assert_eq!(over_product_limits(&m(ImageBudget { stack_boot_b: None, ..ok })).len(), 1);
}
