//! Reduction study (docs/reduction.md): an f64 prototype of the firmware's reduced
//! model (6 slow states, quasi-steady oil ring) with switches, driven by the
//! reference's sensor signals every 10 ms in closed loop with the guard's valve, to
//! measure what each simplification costs in drain error. Prints the error every
//! `every` samples (and the prototype's losses and case/pump balances against the
//! reference's equations) and the max |error| at the end.
//!
//! `cargo run --release -p eha-sim --example reduction_study -- <run> <every> <flags>`
//! with `<run>` = a random-mission seed, `lng`, `case2` or `c1-<bar>`, and flags:
//! `e` the ring keeps its energy, `k` film k/Pr at 40 °C, `p` oil c_p at 40 °C,
//! `l` outer convection as the c0 + c1 dT^(1/4) fit, `0` no ring-rate term in the
//! links. Environment: `DELAY=1` the exchanger's transport delay to the drain
//! feed (times the residence time), `TABN=n` n-point conductance tables,
//! `LINH=1` / `LINR=1` linear convection / radiation (with `l`), `MR=n` one step
//! per n ticks with every loss from the mean inputs.
use eha_guard::{GuardConfig, GuardOf, Restore};
use eha_sim::heat;
use eha_sim::network::{self, Node, Shape};
use eha_sim::plant::{Control, Plant, Sensors};
use eha_sim::rig::Rig;
use std::f64::consts::PI;

#[derive(Clone, Copy, Debug, Default)]
struct Opts {
    const_props: bool,
    const_cp: bool,
    lin_outer: bool,
    h: f64,
    energy: bool,
    no_r: bool,
    tab_n: usize,
    delay: f64,
}

// states: 0 pump, 1 case, 2 loop, 3 main block, 4 ball block, 5 actuator
struct Rpm {
    rig: Rig,
    t: [f64; 6],
    fast: [f64; 4], // inlet, outlet, ballo, (unused)
    r: f64,
    e: f64,
    fast_prev: [f64; 4],
    hist: Vec<bool>,
    dbg: [f64; 5],
    dbg_q: [f64; 6],
    dbg_t: [f64; 6],
    o: Opts,
}

impl Rpm {
    fn cp(&self, t: f64) -> f64 {
        if self.o.const_cp { self.rig.oil.cp(40.0) } else { self.rig.oil.cp(t) }
    }
    fn duct(&self, q: f64, d: f64, len: f64, scale: f64, t: f64) -> f64 {
        let tt = if self.o.const_props { 40.0 } else { t };
        let f = |q: f64| network::duct_conductance(&self.rig, q, d, len, scale, tt, self.rig.oil.nu_m2_per_s(40.0));
        if self.o.tab_n > 0 { tab(f, q.abs(), 2.0e-3, self.o.tab_n) } else { f(q) }
    }
    fn lng_w(&self, c_oil: f64, t: f64) -> f64 {
        let lng = &self.rig.lng;
        if self.o.tab_n > 0 {
            let g = |c: f64| if c <= 0.0 { 0.0 } else { lng.exchanger_w(c, 100.0) / (100.0 - lng.inlet_c) };
            tab(g, c_oil, 2.0e-3 * 870.0 * 1950.0, self.o.tab_n) * (t - lng.inlet_c)
        } else {
            lng.exchanger_w(c_oil, t)
        }
    }
    fn outer(&self, area: f64, shape: Shape, tw: f64, ta: f64) -> f64 {
        if self.o.lin_outer {
            // h_conv = c0 + c1 |dT|^(1/4) fitted at 20 degC ambient; radiation exact
            let (c0, c1) = fit_conv(shape);
            let (c0, c1) = if std::env::var("LINH").is_ok() { (c0 + c1 * 5f64.sqrt().sqrt(), 0.0) } else { (c0, c1) };
            let dt = tw - ta;
            let conv = (c0 + c1 * dt.abs().sqrt().sqrt()) * area * dt;
            let rad = if std::env::var("LINR").is_ok() { 4.0 * 5.670374e-8 * self.rig.outside.emissivity * area * (ta + 273.15 + 2.5f64).powi(3) * dt } else { heat::radiation_w(self.rig.outside.emissivity, area, tw, ta) };
            conv + rad
        } else {
            network::q_outer(&self.rig, area, shape, tw, ta, 0.0)
        }
    }
    /// One step of h with sensor inputs.
    fn step(&mut self, s: &Sensors, v_mps: f64, v2: f64, lng: bool) {
        let rig = &self.rig;
        let h = self.o.h;
        let rho = rig.oil.rho(40.0, 0.0);
        let d = rig.displacement_m3_per_rad();
        let w = s.speed_rpm * PI / 30.0;
        let pa = s.p_a_bar * 1e5;
        let pb = s.p_b_bar * 1e5;
        let pc = rig.hydraulics.accumulator_pa;
        let k = rig.pump.gaps.conductance(rig.oil.mu_pa_s(40.0));
        let dp = pa - pb;
        let leak_a = k * (pa - pc);
        let leak_b = k * (pb - pc);
        let m_l = rho * (leak_a.max(0.0) + leak_b.max(0.0));
        let area = rig.actuator.ram_area_m2;
        let q_pump = d * w - leak_a; // into the A side, what leaves the pump
        let q_act = area * v_mps;
        let q_thr = q_pump - q_act;
        let qc = q_pump; // ring circulation through the pump
        // losses
        let p_leak = leak_a * (pa - pc) + leak_b * (pb - pc);
        let p_mech = rig.pump.eta_m * d * dp.abs() * w.abs();
        let nu40 = rig.oil.nu_m2_per_s(40.0);
        let line = rig.hydraulics.path.power_w(q_thr, nu40, rho).max(0.0);
        let needle = (dp * q_thr - line).max(0.0);
        let act = rig.actuator.leak_m3_per_s_pa * dp * dp + rig.actuator.viscous_friction_n_s_per_m * v2;
        let f_out = rig.pump.mech_to_outlet;
        self.dbg = [p_leak, p_mech, line, needle, m_l];
        // conductances
        let p = &rig.pump;
        let b = &rig.blocks;
        let [tp, tc, tl, tmb, tbb, tact] = self.t;
        let v_rot = w.abs() * p.rotor_radius_m;
        let q_rot = v_rot * PI * 0.25 * p.case_gap_m * p.case_gap_m;
        let g_case = self.duct(q_rot, p.case_gap_m, p.case_gap_m * 10.0, 1.0, tc) / (PI * p.case_gap_m * p.case_gap_m * 10.0) * p.case_wetted_m2;
        let [ti0, to0, tb0, _] = self.fast;
        let g_in = self.duct(qc, p.port_d_m, p.port_len_m, p.port_area_scale, ti0);
        let g_out = self.duct(qc, p.port_d_m, p.port_len_m, p.port_area_scale, to0);
        let g_loop = network::block_path(rig, self.duct(qc, b.loop_d_m, b.loop_len_m, b.loop_area_scale, tl), b.main_area_m2);
        let g_ball = network::block_path(rig, self.duct(qc, b.ball_d_m, b.ball_len_m, 1.0, tb0), b.ball_area_m2);
        let g_tidal = rho * q_act.abs() * self.cp(tl);
        // ring: fast nodes quasi-steady, moving at the loop node's rate r (previous step's)
        let hp_is_out = pa >= pb;
        let m_c = rho * qc.abs();
        let m_thr = (rho * q_thr.abs()).min(m_c);
        let m_act = m_c - m_thr;
        let cpl = self.cp(tl);
        let c_port = rho * p.port_oil_m3 * cpl;
        let c_ball = rho * b.ball_oil_m3 * cpl;
        let r = if self.o.no_r { 0.0 } else { self.r };
        self.hist.push(lng);
        let lng_now = lng;
        let lng_del = if self.o.delay > 0.0 {
            let m0 = (rho * qc.abs() + m_l) * self.cp(tl);
            let tau = self.o.delay * 2.0 * rho * p.port_oil_m3 * self.cp(tl) / m0.max(1e-9);
            let d = (tau / h).round() as usize;
            let n = self.hist.len();
            if d >= n { false } else { self.hist[n - 1 - d] }
        } else { lng };
        let (mut t_in, mut t_out, mut t_ballo, mut q_lng, mut t_hp, mut q_ret) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
        let tl = tl;
        let c_l = rho * cpl * (b.loop_oil_m3 + b.sensor_oil_m3);
        let _ = c_l;
        let mut t_hp_del = 0.0;
        for pass in 0..2 {
        let lng = if pass == 0 { lng_del } else { lng_now };
        let node = |m_in_t: f64, m_out: f64, g: f64, tm: f64, pw: f64, c: f64| (m_in_t + g * tm + pw - c * r) / (m_out * cpl + g);
        if qc >= 0.0 {
            let m0 = m_c + m_l;
            let ql = if lng { self.lng_w(m0 * cpl, tl) } else { 0.0 };
            let p_in = if hp_is_out { 0.0 } else { f_out * p_mech };
            let ti = node(m0 * cpl * tl - ql, m0, g_in, tp, p_in, c_port);
            let m1 = if hp_is_out { m0 } else { m_c };
            let p_out = if hp_is_out { f_out * p_mech } else { 0.0 };
            let to = node(m1 * cpl * ti, m1, g_out, tp, p_out, c_port);
            let tb = node(m_thr * cpl * to, m_thr, g_ball, tbb, needle, c_ball);
            t_in = ti; t_out = to; t_ballo = tb; q_lng = ql;
            t_hp = if hp_is_out { to } else { ti };
            q_ret = m_thr * cpl * tb + m_act * cpl * to; // inflow enthalpy into the loop (besides leak)
        } else {
            let m0 = m_c + m_l;
            let ql = if lng { self.lng_w(m0 * cpl, tl) } else { 0.0 };
            let t_src = tl - if m0 > 0.0 { ql / (m0 * cpl) } else { 0.0 };
            let (fb, fa) = if m_c > 0.0 { (m_thr / m_c, m_act / m_c) } else { (0.0, 1.0) };
            let mb_ = m_thr + m_l * fb;
            let tb = node(mb_ * cpl * t_src, mb_, g_ball, tbb, needle, c_ball);
            let md = m_act + m_l * fa;
            let p_out = if hp_is_out { f_out * p_mech } else { 0.0 };
            let to = node(mb_ * cpl * tb + md * cpl * t_src, m0, g_out, tp, p_out, c_port);
            let m2 = if hp_is_out { m_c } else { m0 };
            let p_in = if hp_is_out { 0.0 } else { f_out * p_mech };
            let ti = node(m2 * cpl * to, m2, g_in, tp, p_in, c_port);
            t_in = ti; t_out = to; t_ballo = tb; q_lng = ql;
            t_hp = if hp_is_out { to } else { ti };
            q_ret = m_c * cpl * ti;
        }
        if pass == 0 { t_hp_del = t_hp; }
        }
        self.t[2] = tl;
        self.fast = [t_in, t_out, t_ballo, 0.0];
        // slow derivatives (W)
        let amb = s.ambient_c;
        let q_pump = g_case * (tc - tp) + g_in * (t_in - tp) + g_out * (t_out - tp)
            - self.outer(p.area_m2, Shape::Cylinder(p.diameter_m), tp, amb);
        let cpm = |a: f64, b: f64| self.cp(0.5 * (a + b));
        let t_feed = if self.o.delay > 0.0 { t_hp_del } else { t_hp };
        let q_case = p_leak + (1.0 - f_out) * p_mech + g_case * (tp - tc) + m_l * cpm(t_feed, tc) * (t_feed - tc);
        let q_tot = line + needle + f_out * p_mech + g_in * (tp - t_in) + g_out * (tp - t_out) + g_ball * (tbb - t_ballo) + g_loop * (tmb - tl)
            + m_l * cpm(tc, t_feed) * (tc - t_feed) - q_lng + g_tidal * (tact - tl);
        let q_ring = q_ret - m_c * cpl * tl + m_l * cpm(tc, tl) * (tc - tl) + line + g_loop * (tmb - tl) + g_tidal * (tact - tl);
        let side = |a: f64| (a / 6.0).sqrt();
        let q_mb = g_loop * (tl - tmb) - self.outer(b.main_area_m2, Shape::Cube(side(b.main_area_m2)), tmb, amb);
        let q_bb = g_ball * (t_ballo - tbb) - self.outer(b.ball_area_m2, Shape::Cube(side(b.ball_area_m2)), tbb, amb);
        let a = &rig.actuator;
        let q_act = act + g_tidal * (tl - tact) - self.outer(a.area_m2, Shape::Cylinder(a.diameter_m), tact, amb);
        let c_ring = rho * cpl * (b.loop_oil_m3 + b.sensor_oil_m3);
        let caps = [p.mass_kg * p.cp, rho * p.case_oil_m3 * self.cp(tc), c_ring, b.main_mass_kg * b.cp, b.ball_mass_kg * b.cp, a.body_mass_kg * a.body_cp];
        let q = [q_pump, q_case, q_ring, q_mb, q_bb, q_act];
        self.dbg_q = q;
        self.dbg[4] = m_l; self.dbg[2] = t_hp; self.dbg[3] = cpl;
        self.dbg_t = [tp, tc, tl, t_in, t_out, t_ballo];
        for i in 0..6 {
            self.t[i] += h * q[i] / caps[i];
        }
        self.r = q_ring / c_ring;
        if self.o.energy {
            // energy-consistent: the loop takes the ring's total heat minus what the
            // quasi-steady fast nodes stored (their change since the last step).
            let c_tot = c_ring + 2.0 * c_port + c_ball;
            let [fi, fo, fb, _] = self.fast_prev;
            let stored = c_port * (t_in - fi) + c_port * (t_out - fo) + c_ball * (t_ballo - fb);
            self.t[2] = tl + (h * q_tot - stored) / c_ring;
            self.r = q_tot / c_tot;
        }
        self.fast_prev = self.fast;
        let _ = m_act;
    }
}

fn tab(f: impl Fn(f64) -> f64, x: f64, xmax: f64, n: usize) -> f64 {
    let u = (x / xmax).min(1.0).sqrt() * (n - 1) as f64;
    let j = (u.floor() as usize).min(n - 2);
    let fr = u - j as f64;
    let x0 = xmax * (j as f64 / (n - 1) as f64).powi(2);
    let x1 = xmax * ((j + 1) as f64 / (n - 1) as f64).powi(2);
    f(x0) * (1.0 - fr) + f(x1) * fr
}

fn fit_conv(shape: Shape) -> (f64, f64) {
    // least squares of h(dT) = c0 + c1 dT^0.25 over dT in (0.05, 40) K at 20 degC ambient
    let (mut s11, mut s12, mut s22, mut b1, mut b2) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut dt = 0.05;
    while dt < 40.0 {
        let h = match shape { Shape::Cylinder(d) => heat::h_free_cylinder(20.0 + dt, 20.0, d), Shape::Cube(a) => heat::h_free_cube(20.0 + dt, 20.0, a) };
        let x = dt.sqrt().sqrt();
        let w = 1.0;
        s11 += w; s12 += w * x; s22 += w * x * x; b1 += w * h; b2 += w * h * x;
        dt *= 1.1;
    }
    let det = s11 * s22 - s12 * s12;
    ((b1 * s22 - b2 * s12) / det, (s11 * b2 - s12 * b1) / det)
}

fn main() {
    let arg = std::env::args().nth(1).unwrap_or("4".into());
    let every: usize = std::env::args().nth(2).and_then(|s| s.parse().ok()).unwrap_or(100000);
    let flags = std::env::args().nth(3).unwrap_or_default();
    let Some(sc) = eha_sim::missions::run_by_name(&arg) else {
        eprintln!("unknown run {arg:?}: expected lng, case2, c1-<bar> or a random-mission seed");
        std::process::exit(2);
    };
    let rig = Rig::default();
    let mut plant = Plant::new(&rig, &sc).unwrap();
    let refm = eha_sim::model::Model::new(rig.clone(), eha_sim::model::Drive::Mission(sc.mission().unwrap()));
    let cfg = GuardConfig::DEFAULT;
    let mut guard = GuardOf::<f64>::new(&cfg, Restore::Cold);
    let o = Opts { const_props: flags.contains("k"), const_cp: flags.contains("p"), lin_outer: flags.contains("l"), h: 0.01 * std::env::var("MR").ok().and_then(|v| v.parse::<f64>().ok()).unwrap_or(1.0), energy: flags.contains("e"), no_r: flags.contains("0"), tab_n: std::env::var("TABN").ok().and_then(|v| v.parse().ok()).unwrap_or(0), delay: std::env::var("DELAY").ok().and_then(|v| v.parse().ok()).unwrap_or(0.0) };
    let _ = o.lin_outer;
    let mut m = Rpm { rig: rig.clone(), t: [0.0; 6], fast: [0.0; 4], r: 0.0, e: 0.0, fast_prev: [0.0; 4], hist: vec![], dbg: [0.0; 5], dbg_q: [0.0; 6], dbg_t: [0.0; 6], o };
    let mut k = 0usize;
    let mut prev_x = 0.0;
    let mr: usize = std::env::var("MR").ok().and_then(|v| v.parse().ok()).unwrap_or(1);
    let mut acc = Sensors { t: 0.0, current_a: 0.0, p_a_bar: 0.0, p_b_bar: 0.0, speed_rpm: 0.0, position_mm: 0.0, ambient_c: 0.0, t_drain_c: 0.0, t_loop_oil_c: 0.0, lng_open: false };
    let mut nacc = 0usize;
    let (mut max_e, mut max_g) = (0.0f64, 0.0f64);
    plant.run(0.01, 600.0, |snap| {
        let s = Sensors::from(snap);
        let out = guard.step(&s.sample());
        if k == 0 {
            m.t = [s.ambient_c; 6];
            m.fast = [s.ambient_c; 4];
            m.fast_prev = [s.ambient_c; 4];
            m.e = s.ambient_c * rig.oil.rho(40.0, 0.0) * rig.oil.cp(40.0) * (rig.blocks.loop_oil_m3 + rig.blocks.sensor_oil_m3 + 2.0 * rig.pump.port_oil_m3 + rig.blocks.ball_oil_m3);
            prev_x = s.position_mm;
        }
        let e = m.t[1] - s.t_drain_c;
        if k > 0 {
            max_e = max_e.max(e.abs());
            max_g = max_g.max((out.drain_c as f64 - s.t_drain_c).abs());
        }
        if k % every == 0 {
            let l = &snap.losses;
            println!("  rpm {:5.0} pa {:6.1} pb {:6.1} | leak {:7.2}/{:7.2} mech {:7.2}/{:7.2} line {:7.2}/{:7.2} needle {:7.2}/{:7.2} valves {:6.2}", s.speed_rpm, s.p_a_bar, s.p_b_bar, m.dbg[0], l.leakage, m.dbg[1], l.mechanical, m.dbg[2], l.line, m.dbg[3], l.needle, l.valves);
            println!("{:6.1} lng {} drain {:6.2} rpm e {:+.4} (pump {:+.3} loop {:+.3} mb {:+.3} bb {:+.3} act {:+.3}) guard e {:+.3} | in {:+.3} out {:+.3} ballo {:+.3}", s.t, out.valve_open as u8, s.t_drain_c, e,
                m.t[0] - snap.temp(Node::Pump), m.t[2] - snap.temp(Node::Loop), m.t[3] - snap.temp(Node::MainBlock), m.t[4] - snap.temp(Node::BallBlock), m.t[5] - snap.temp(Node::Actuator), out.drain_c as f64 - s.t_drain_c, m.fast[0]-snap.temp(Node::Inlet), m.fast[1]-snap.temp(Node::Outlet), m.fast[2]-snap.temp(Node::BallOil));
        }
        if k % every == 1 && k > 1 {
            let mut tt = snap.temps;
            let [tp, tc, tl, ti, to, tb] = m.dbg_t;
            tt[Node::Pump as usize] = tp; tt[Node::Case as usize] = tc; tt[Node::Loop as usize] = tl; tt[Node::Inlet as usize] = ti; tt[Node::Outlet as usize] = to; tt[Node::BallOil as usize] = tb;
            tt[Node::MainBlock as usize] = m.t[3]; tt[Node::BallBlock as usize] = m.t[4]; tt[Node::Actuator as usize] = m.t[5]; tt[Node::Sensor as usize] = tl;
            let mut dt = [0.0; 12];
            refm.thermal(&snap.op, &snap.losses, &tt, &mut dt);
            let cc = rig.oil.rho(40.0,0.0) * rig.pump.case_oil_m3 * rig.oil.cp(tc);
            let o = &rig.oil;
            println!("   m_l {:.3e} t_hp {:.3} tc {:.3} cpl {:.2} adv mine {:.3} ref {:.3}", m.dbg[4], m.dbg[2], tc, m.dbg[3], m.dbg[4]*m.dbg[3]*(m.dbg[2]-tc), m.dbg[4]*(o.enthalpy(m.dbg[2])-o.enthalpy(tc)));
            println!("   case q mine {:8.3} ref-eq {:8.3}  pump mine {:8.3} ref-eq {:8.3}", m.dbg_q[1], dt[Node::Case as usize] * cc, m.dbg_q[0], dt[Node::Pump as usize] * 9200.0);
        }
        // accumulate mr ticks, then one model step of mr*10 ms with the means
        acc.p_a_bar += s.p_a_bar; acc.p_b_bar += s.p_b_bar; acc.speed_rpm += s.speed_rpm; acc.current_a += s.current_a * s.current_a; acc.ambient_c += s.ambient_c;
        nacc += 1;
        if nacc == mr {
            let f = 1.0 / mr as f64;
            let mut a = s;
            a.p_a_bar = acc.p_a_bar * f; a.p_b_bar = acc.p_b_bar * f; a.speed_rpm = acc.speed_rpm * f; a.current_a = (acc.current_a * f).sqrt(); a.ambient_c = acc.ambient_c * f;
            let v = (s.position_mm - prev_x) * 1e-3 / (0.01 * mr as f64);
            prev_x = s.position_mm;
            m.step(&a, v, v * v, out.valve_open);
            acc = Sensors { t: 0.0, current_a: 0.0, p_a_bar: 0.0, p_b_bar: 0.0, speed_rpm: 0.0, position_mm: 0.0, ambient_c: 0.0, t_drain_c: 0.0, t_loop_oil_c: 0.0, lng_open: false };
            nacc = 0;
        }
        refm.lng_open.set(out.valve_open);
        k += 1;
        Ok(Control { lng_valve: Some(out.valve_open), stop: false })
    })
    .unwrap();
    let _ = heat::series;
    println!("{arg}: max |e| rpm {max_e:.4} guard {max_g:.3}");
}
