"""The FMUs in a real importer (FMPy): validation, the plant on Case 1 against
the native run, and plant + guard in closed loop on Fig. 15 against the SIL
run. Called by .ci/fmu-check with the FMU directory and the native outputs;
exits non-zero on the first failed check, printing what was measured.

Usage: fmpy_check.py FMU_DIR NATIVE_CASE1_CSV SIL_FIG15_CSV
"""

import csv
import sys

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.simulation import simulate_fmu
from fmpy.validation import validate_fmu


def load_csv(path):
    """A measured-data CSV (`# key: value` lines, header, rows) as columns;
    empty cells are NaN."""
    with open(path) as f:
        rows = [line for line in f if not line.startswith("#")]
    table = list(csv.reader(rows))
    header, body = table[0], table[1:]
    data = np.array([[float(x) if x != "" else np.nan for x in r] for r in body])
    return {h: data[:, i] for i, h in enumerate(header)}


def check_validation(fmu_dir):
    """(a) FMPy's checker finds no problem in either FMU."""
    for name in ("EhaPlant", "EhaGuard"):
        problems = validate_fmu(f"{fmu_dir}/{name}.fmu")
        if problems:
            sys.exit(f"(a) {name}.fmu: FMPy validation failed:\n" + "\n".join(problems))
        print(f"(a) {name}.fmu: FMPy validation passed")


def check_case1(fmu_dir, native_csv):
    """(b) The plant FMU on Case 1 (60 bar, 600 s, 1 s steps) against
    `eha-sim simulate`: every channel within 1e-6 of its largest magnitude,
    plus the CSV's 6-decimal rounding (5e-7) the native file carries. Both
    run the same BDF with the same history (the FMU keeps its solver across
    communication points), so the difference is that rounding."""
    nat = load_csv(native_csv)
    names = [n for n in nat if n != "time_s"]
    r = simulate_fmu(
        f"{fmu_dir}/EhaPlant.fmu",
        start_values={"cmd_needle_bar": 60.0, "cmd_speed_rpm": 500.0, "in_ambient_c": 16.0},
        stop_time=600.0,
        output_interval=1.0,
        output=names,
    )
    if len(r) != len(nat["time_s"]) or np.max(np.abs(r["time"] - nat["time_s"])) > 1e-9:
        sys.exit(f"(b) output grids differ: FMU {len(r)} rows, native {len(nat['time_s'])}")
    worst = (0.0, "", 0.0)
    for n in names:
        diff = float(np.max(np.abs(r[n] - nat[n])))
        scale = float(np.max(np.abs(nat[n])))
        bound = 1e-6 * scale + 5e-7
        if diff > bound:
            sys.exit(f"(b) {n}: FMU vs native max |diff| {diff:.3e} > {bound:.3e} (1e-6 x {scale:.4g} + CSV rounding)")
        if scale > 0 and diff / scale > worst[0]:
            worst = (diff / scale, n, diff)
    print(f"(b) Case 1: {len(names)} channels x {len(r)} points within 1e-6 relative (+CSV rounding); worst {worst[1]} {worst[2]:.2e} ({worst[0]:.2e} relative)")


def slave(fmu_dir, name, instance):
    md = read_model_description(f"{fmu_dir}/{name}.fmu")
    unzipped = extract(f"{fmu_dir}/{name}.fmu")
    s = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier, instanceName=instance)
    vrs = {v.name: v.valueReference for v in md.modelVariables}
    return s, vrs


def check_closed_loop(fmu_dir, sil_csv):
    """(c) Plant FMU + guard FMU coupled in FMPy on Fig. 15 (Case 1 at 60 bar,
    LNG valve from the guard), 10 ms steps, against the SIL run
    (`eha-sim pil --sil`: the same firmware core and plant in Rust). The
    master does what the SIL loop does each tick: the plant's sample and
    valve read-back to the guard, the guard's valve command to the plant."""
    sil = load_csv(sil_csv)
    n = len(sil["time_s"])
    tick = 0.01
    plant, pv = slave(fmu_dir, "EhaPlant", "plant")
    guard, gv = slave(fmu_dir, "EhaGuard", "guard")
    plant.instantiate()
    guard.instantiate()
    # The SIL loop runs the plant one tick past its last sample.
    plant.setupExperiment(startTime=0.0, stopTime=(n + 1) * tick)
    guard.setupExperiment(startTime=0.0)
    plant.enterInitializationMode()
    plant.setReal([pv["cmd_needle_bar"], pv["cmd_speed_rpm"], pv["in_ambient_c"]], [60.0, 500.0, 16.0])
    plant.exitInitializationMode()
    guard.enterInitializationMode()
    guard.exitInitializationMode()
    sample = ["current_a", "p_a_bar", "p_b_bar", "speed_rpm", "position_mm", "ambient_c"]
    p_out = [pv[x] for x in sample] + [pv["lng_valve"], pv["t_drain_c"]]
    g_in = [gv[x] for x in sample]
    est = np.empty(n)
    valve = np.empty(n, dtype=bool)
    for k in range(n):
        t = k * tick
        y = plant.getReal(p_out)
        guard.setReal(g_in, y[:6])
        guard.setInteger([gv["valve_feedback"]], [int(y[6] > 0.5)])
        guard.doStep(currentCommunicationPoint=t, communicationStepSize=tick)
        est[k] = guard.getReal([gv["drain_c"]])[0]
        valve[k] = guard.getBoolean([gv["valve_open"]])[0]
        plant.setBoolean([pv["cmd_lng_valve"]], [bool(valve[k])])
        plant.doStep(currentCommunicationPoint=t, communicationStepSize=tick)
    for s in (plant, guard):
        s.terminate()
        s.freeInstance()
    sil_valve = sil["lng_valve"] > 0.5
    edges = lambda v: np.nonzero(np.diff(v.astype(int)))[0] + 1
    fe, se = edges(valve), edges(sil_valve)
    if len(fe) != len(se) or (len(fe) and np.max(np.abs(fe - se)) > 1):
        sys.exit(f"(c) valve events differ: FMU ticks {fe.tolist()}, SIL ticks {se.tolist()}")
    # The SIL CSV holds each f32 estimate as its shortest decimal: back to
    # f32, it is the firmware's value bit for bit.
    same = np.float32(est) == np.float32(sil["fw_drain_c"])
    d = float(np.max(np.abs(est - sil["fw_drain_c"])))
    if not same.all():
        k = int(np.argmin(same))
        sys.exit(f"(c) drain estimate differs from the SIL run at {int((~same).sum())} ticks (first tick {k}: FMU {est[k]!r}, SIL {sil['fw_drain_c'][k]!r})")
    print(f"(c) Fig. 15 closed loop: {n} ticks, valve events at ticks {fe.tolist()} (SIL {se.tolist()}), estimate bit-identical in f32 at every tick (|diff| {d:.1e} K is the CSV's decimal form)")


if __name__ == "__main__":
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    fmu_dir, native_csv, sil_csv = sys.argv[1:]
    check_validation(fmu_dir)
    check_case1(fmu_dir, native_csv)
    check_closed_loop(fmu_dir, sil_csv)
    print("FMU checks passed")
