//! SI parameters of the reduced-order model (design side, `f64`).
//!
//! Everything is plain SI so that the reduction tool in `host-tests`
//! (`eha_sim::reduce`) can derive every field from the reference rig and
//! regenerate [`DEFAULT`] with plain literals. The firmware never steps with these
//! numbers directly: [`crate::model::Model::new`] converts them once into model units
//! of the firmware's number type and builds the exact-ZOH matrix.
//!
//! Node order (fixed): `0 pump housing, 1 drain (case) oil, 2 loop oil, 3 main
//! valve block, 4 ball/needle-valve block, 5 actuator body` ([`NODE_PUMP`] ...).

pub use crate::default_consts::DEFAULT_CONSTS;

/// Number of thermal states of the reduced model.
pub const N_NODES: usize = 6;
/// Node index: pump housing (rig measurement Point 3), J/K capacity [`ReducedParams::pump_j_per_k`].
pub const NODE_PUMP: usize = 0;
/// Node index: oil in the pump case, which leaves through the drain port (the protected temperature).
pub const NODE_DRAIN: usize = 1;
/// Node index: circulating oil of the main-block passages, hoses and accumulator side.
pub const NODE_LOOP: usize = 2;
/// Node index: main valve block (Point 4).
pub const NODE_MAIN_BLOCK: usize = 3;
/// Node index: ball/needle-valve block (Point 5).
pub const NODE_BALL_BLOCK: usize = 4;
/// Node index: actuator body with its chamber oil.
pub const NODE_ACTUATOR: usize = 5;
/// Metal nodes that see the air, in the order of the `outer_*` arrays.
pub const OUTER_NODES: [usize; 4] = [NODE_PUMP, NODE_MAIN_BLOCK, NODE_BALL_BLOCK, NODE_ACTUATOR];

/// Points of every conductance table. Grid `x_j = x_max (j / (N_TABLE - 1))^2`:
/// uniform in `sqrt(x)`, dense at low flow where the laminar film laws
/// (Nu ∝ (Re Pr d/L)^(1/3)) are steepest.
pub const N_TABLE: usize = 32;

/// Sample interval of the controller (one [`crate::Guard`] tick), s.
pub const S_PER_TICK: f64 = 0.01;
/// Ticks per model step.
pub const TICKS_PER_STEP: u32 = 10;
/// Model step, s: the thermal state advances every [`TICKS_PER_STEP`] ticks
/// (100 ms) with the tick-averaged losses and flows. The fastest thermal state (the
/// case oil, 0.25 kJ/K against ≈ 7 W/K) has a time constant of ≈ 35 s.
pub const S_PER_STEP: f64 = S_PER_TICK * TICKS_PER_STEP as f64;

/// Reduced-order model parameters, SI units, `f64`.
///
/// Continuous model (docs/firmware.md): six slow nodes; the pump's port passages
/// and the ball-valve oil are quasi-steady links of the oil ring (their capacity is
/// small against the circulating flow); losses of eqs. (1)-(11); conductances of
/// eqs. (12)-(19) tabulated over flow; the LNG exchanger of eqs. (20)-(22).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReducedParams {
    /// Heat capacity of the pump housing, J/K (Table 2: 20 kg steel).
    pub pump_j_per_k: f64,
    /// Heat capacity of the main valve block, J/K.
    pub main_block_j_per_k: f64,
    /// Heat capacity of the ball/needle-valve block, J/K.
    pub ball_block_j_per_k: f64,
    /// Heat capacity of the actuator body, J/K.
    pub actuator_j_per_k: f64,
    /// Oil volume of the pump case (the drain node), m^3.
    pub case_oil_m3: f64,
    /// Oil volume of the loop node (main-block passages, hoses, sensor pocket), m^3.
    pub loop_oil_m3: f64,
    /// Oil volume of one pump port passage (inlet = outlet), m^3 (quasi-steady link).
    pub port_oil_m3: f64,
    /// Oil volume of the ball/needle-valve passage, m^3 (quasi-steady link).
    pub ball_oil_m3: f64,
    /// Oil density at 40 degC, kg/m^3.
    pub rho_kg_per_m3: f64,
    /// Oil specific heat at 20 degC, J/(kg K).
    pub cp20_j_per_kg_k: f64,
    /// Slope of the oil specific heat, J/(kg K^2) (`cp = cp20 + slope (T - 20)`).
    pub cp_slope_j_per_kg_k2: f64,
    /// Pump displacement per radian, m^3/rad (19 cm^3/rev / 2 pi).
    pub displacement_m3_per_rad: f64,
    /// Pump friction, pressure term `eta_m` (eq. 8: `P = eta_m D |dp| |w|`).
    pub eta_m: f64,
    /// Pump friction, no-load torque `T0` of the extended eq. (8), N m: heat
    /// `T0 |w|` into the pump housing (bearings, shaft seal).
    pub no_load_torque_nm: f64,
    /// Pump friction, viscous term of the extended eq. (8) at the 40 degC
    /// viscosity, W per (rad/s)^2: heat `C_v mu D w^2`, split like the pressure term.
    pub viscous_w_s2_per_rad2: f64,
    /// Share of the pump's viscous and pressure friction heating the delivered
    /// (high-pressure port) oil (sliding-pair rule of the reference), dimensionless.
    pub mech_to_outlet: f64,
    /// Share of the pump's viscous and pressure friction heating the case oil; the
    /// rest, `1 - mech_to_outlet - mech_to_case`, heats the pump housing.
    pub mech_to_case: f64,
    /// Oil volumetric expansion coefficient alpha, 1/K: the pump's compression
    /// warms the delivered oil by `alpha T dp / (rho c_p)` and every throttling
    /// releases `(1 - alpha T) dp q` as heat (enthalpy h(T, p), T absolute).
    pub expansion_per_k: f64,
    /// Pump leakage flow conductance of the gaps (eqs. 5-7), m^3/(s Pa), at `t_mu_ref_c`:
    /// each port leaks `K (p_port - p_case)` into the case.
    pub k_leak_m3_per_s_pa: f64,
    /// Case (accumulator) pressure, Pa gauge.
    pub case_pressure_pa: f64,
    /// Viscosity-temperature exponent: the leakage conductance scales by
    /// `exp(k_mu (T_drain - t_mu_ref_c))` (mu falls as T rises), 1/K; 0 holds the
    /// viscosity at its reference value, as the reference baseline does.
    pub k_mu_per_k: f64,
    /// Reference temperature of the leakage conductance, degC.
    pub t_mu_ref_c: f64,
    /// Laminar resistance of the throttle path's line (eq. 10, Hagen-Poiseuille),
    /// Pa s/m^3: line loss `P = R1 q^2 + R2 |q|^3`.
    pub line_r1_pa_s_per_m3: f64,
    /// Local-loss resistance of the throttle path's line (eq. 10, sum of xi), Pa s^2/m^6.
    pub line_r2_pa_s2_per_m6: f64,
    /// Effective ram area of the cylinder, m^2 (Table 3: 1526.81 mm^2).
    pub ram_area_m2: f64,
    /// Cross-piston leakage conductance of the actuator, m^3/(s Pa) (eq. 11).
    pub act_leak_m3_per_s_pa: f64,
    /// Viscous seal friction of the piston, N s/m (heat `F v` into the actuator body).
    pub act_friction_n_s_per_m: f64,
    /// Motor phases `m` (eq. 1; copper loss, for the dissipation total only).
    pub phases: f64,
    /// Phase resistance, ohm (eq. 1; constant, as in the reference baseline).
    pub r_ohm: f64,
    /// Motor torque constant, N m per A rms: the shaft torque is `Kt |I|`. Used only
    /// by the sensor cross-check (shaft power `Kt |I| |w|` against the hydraulic
    /// power and eq. 8); 0 disables the cross-check.
    pub torque_constant_nm_per_a: f64,
    /// Iron loss, hysteresis term: `k_fe1 |w|`, W s/rad (eq. 2 with f ∝ w).
    pub k_fe1_w_s_per_rad: f64,
    /// Iron loss, eddy term: `k_fe2 w^2`, W s^2/rad^2 (eq. 2).
    pub k_fe2_w_s2_per_rad2: f64,
    /// Iron loss, excess term: `k_fe15 |w|^1.5`, W (s/rad)^1.5 (eq. 2).
    pub k_fe15_w_per_rad15: f64,
    /// Shaft speed at the last point of the case-oil table, rad/s.
    pub speed_table_max_rad_s: f64,
    /// Flow at the last point of the flow tables, m^3/s.
    pub flow_table_max_m3_per_s: f64,
    /// Case oil <-> pump housing conductance over shaft speed (film of the oil
    /// stirred by the rotating group, eqs. 12-14), W/K.
    pub g_case_w_per_k: [f64; N_TABLE],
    /// One port passage <-> pump housing conductance over circulating flow (eqs. 12-14), W/K.
    pub g_port_w_per_k: [f64; N_TABLE],
    /// Loop oil <-> main block over circulating flow: duct film in series with the
    /// block wall (eqs. 12-14, 18), W/K.
    pub g_loop_block_w_per_k: [f64; N_TABLE],
    /// Ball-valve oil <-> ball-valve block over circulating flow (eqs. 12-14, 18), W/K.
    pub g_ball_block_w_per_k: [f64; N_TABLE],
    /// LNG exchanger conductance `eps(NTU, C*) C_min` over the oil flow through it
    /// (eqs. 20-22), W/K; the heat removed is this times `T_loop - lng_inlet_c`.
    pub g_lng_w_per_k: [f64; N_TABLE],
    /// LNG inlet temperature (Table 6 context: -162 degC), degC.
    pub lng_inlet_c: f64,
    /// Outer surfaces of [`OUTER_NODES`]: free-convection conductance, constant part
    /// `A c0` of `h = c0 + c1 |dT|^(1/4)` (eqs. 15-16 fitted), W/K.
    pub outer_w_per_k: [f64; 4],
    /// Outer surfaces: free-convection part `A c1` of `h = c0 + c1 |dT|^(1/4)`, W/K^1.25.
    pub outer_quarter_w_per_k125: [f64; 4],
    /// Outer surfaces: radiation `eps sigma A` (eq. 19, linearised about the mean of
    /// wall and air: `4 eps sigma A T_m^3 dT`), W/K^4.
    pub outer_rad_w_per_k4: [f64; 4],
    /// Jacobian of the model's right-hand side at the nominal operating point
    /// (500 rpm, 30 bar, nodes at 40 degC, air 20 degC), 1/s: the linear part whose
    /// zero-order hold is exact (exponential Euler).
    pub nominal_jacobian_per_s: [[f64; N_NODES]; N_NODES],
    /// The model step's exact-ZOH matrix `Phi = h phi1(h A)` of
    /// [`Self::nominal_jacobian_per_s`] at `h` = [`crate::params::S_PER_STEP`], s:
    /// computed on the host by `eha_sim::reduce` (`crate::model::etd_matrix`, the
    /// 12x12 matrix exponential), so that the firmware does no matrix
    /// exponential at boot.
    pub phi_step_s: [[f64; N_NODES]; N_NODES],
    /// Cooling at rest (pump stopped, no power): decay rate `r_i` of the bound
    /// `T_i(t) - T_air <= c v_i e^(-r_i t)` on the model's temperatures, 1/s,
    /// node order: a Collatz–Wielandt bound of the rest Jacobian per group of
    /// coupled nodes (outer convection at its linear part, radiation at its
    /// tangent: the slowest cooling), computed on the host by
    /// `eha_sim::reduce::rest_cooling`; all 0 = no cooling bound (a restore
    /// after a power loss keeps the saved temperatures).
    pub rest_rate_per_s: [f64; N_NODES],
    /// The bound's mode shape `v` (node order, positive, max 1 in each group
    /// of coupled nodes): the Perron vector of each group.
    pub rest_mode: [f64; N_NODES],
}

impl ReducedParams {
    /// Oil volumetric heat capacity at `t_c`, J/(m^3 K).
    pub fn rho_cp(&self, t_c: f64) -> f64 {
        self.rho_kg_per_m3 * (self.cp20_j_per_kg_k + self.cp_slope_j_per_kg_k2 * (t_c - 20.0))
    }

    /// Physical plausibility: capacities and volumes > 0, conductances and
    /// coefficients >= 0, everything finite. `true` when usable.
    pub fn is_plausible(&self) -> bool {
        let pos = [
            self.pump_j_per_k,
            self.main_block_j_per_k,
            self.ball_block_j_per_k,
            self.actuator_j_per_k,
            self.case_oil_m3,
            self.loop_oil_m3,
            self.port_oil_m3,
            self.ball_oil_m3,
            self.rho_kg_per_m3,
            self.cp20_j_per_kg_k,
            self.speed_table_max_rad_s,
            self.flow_table_max_m3_per_s,
        ]
        .iter()
        .all(|x| x.is_finite() && *x > 0.0);
        let non_neg = [
            self.displacement_m3_per_rad,
            self.eta_m,
            self.no_load_torque_nm,
            self.viscous_w_s2_per_rad2,
            self.mech_to_outlet,
            self.mech_to_case,
            self.expansion_per_k,
            self.k_leak_m3_per_s_pa,
            self.line_r1_pa_s_per_m3,
            self.line_r2_pa_s2_per_m6,
            self.ram_area_m2,
            self.act_leak_m3_per_s_pa,
            self.act_friction_n_s_per_m,
            self.phases,
            self.r_ohm,
            self.torque_constant_nm_per_a,
            self.k_fe1_w_s_per_rad,
            self.k_fe2_w_s2_per_rad2,
            self.k_fe15_w_per_rad15,
        ]
        .iter()
        .chain(self.g_case_w_per_k.iter())
        .chain(self.g_port_w_per_k.iter())
        .chain(self.g_loop_block_w_per_k.iter())
        .chain(self.g_ball_block_w_per_k.iter())
        .chain(self.g_lng_w_per_k.iter())
        .chain(self.outer_w_per_k.iter())
        .chain(self.outer_quarter_w_per_k125.iter())
        .chain(self.outer_rad_w_per_k4.iter())
        .all(|x| x.is_finite() && *x >= 0.0);
        // The quasi-steady links divide by their conductance at zero flow.
        let links = self.g_port_w_per_k.first().is_some_and(|g| *g > 0.0)
            && self.g_ball_block_w_per_k.first().is_some_and(|g| *g > 0.0);
        let finite = [
            self.cp_slope_j_per_kg_k2,
            self.case_pressure_pa,
            self.k_mu_per_k,
            self.t_mu_ref_c,
            self.lng_inlet_c,
        ]
        .iter()
        .chain(self.nominal_jacobian_per_s.iter().flatten())
        .chain(self.phi_step_s.iter().flatten())
        .all(|x| x.is_finite());
        let rest = self.rest_rate_per_s.iter().all(|r| r.is_finite() && *r >= 0.0)
            && self.rest_mode.iter().all(|v| v.is_finite() && (0.0..=1.0).contains(v));
        let split = self.mech_to_outlet + self.mech_to_case <= 1.0;
        let cp_pos = self.rho_cp(-60.0) > 0.0 && self.rho_cp(150.0) > 0.0;
        pos && non_neg && links && finite && split && cp_pos && rest
    }
}

/// Default parameters, reduced from the reference rig `Rig::default()` by
/// `eha_sim::reduce` (docs/reduction.md): nothing is fitted to simulation output.
/// THIS CONSTANT IS REGENERATED BY `cargo run --release -p eha-sim --example reduce`:
/// keep plain literals.
pub const DEFAULT: ReducedParams = ReducedParams {
    pump_j_per_k: 9200.0,
    main_block_j_per_k: 73600.0,
    ball_block_j_per_k: 13800.0,
    actuator_j_per_k: 5520.0,
    case_oil_m3: 0.00015,
    loop_oil_m3: 0.0016797960000000001,
    port_oil_m3: 5e-5,
    ball_oil_m3: 5e-5,
    rho_kg_per_m3: 857.83,
    cp20_j_per_kg_k: 1880.0,
    cp_slope_j_per_kg_k2: 3.7,
    displacement_m3_per_rad: 3.023943918746011e-6,
    eta_m: 0.49826,
    no_load_torque_nm: 0.0,
    viscous_w_s2_per_rad2: 0.0,
    mech_to_outlet: 0.768027,
    mech_to_case: 0.231973,
    expansion_per_k: 0.0,
    k_leak_m3_per_s_pa: 3.3579931725827373e-13,
    case_pressure_pa: 500000.0,
    k_mu_per_k: 0.0,
    t_mu_ref_c: 40.0,
    line_r1_pa_s_per_m3: 588776503.3402456,
    line_r2_pa_s2_per_m6: 1018550987858.2805,
    ram_area_m2: 0.00152681,
    act_leak_m3_per_s_pa: 2e-14,
    act_friction_n_s_per_m: 2000.0,
    phases: 3.0,
    r_ohm: 0.074,
    torque_constant_nm_per_a: 0.75,
    k_fe1_w_s_per_rad: 0.37433242615213785,
    k_fe2_w_s2_per_rad2: 0.0015887161595118564,
    k_fe15_w_per_rad15: 0.008414188516295527,
    speed_table_max_rad_s: 628.3185307179587,
    flow_table_max_m3_per_s: 0.0018999999999999998,
    lng_inlet_c: -162.0,
    g_case_w_per_k: [0.23594499397973182, 0.6213927963218584, 0.9989139364854088, 1.3196645759264543, 1.6068240611444087, 1.8710570624957699, 2.118260227808865, 2.352109092209836, 2.575085480308449, 2.788963219460052, 2.995065085987329, 3.194410492029924, 3.387805954547485, 3.5759033806376412, 3.7592391874690665, 3.9382614644135363, 4.113349378848181, 4.28482738272898, 4.452975834361532, 4.61803908731989, 4.780231751043793, 4.939743606484021, 5.096743515589239, 5.251382566660512, 5.7598908388774115, 6.394469812043816, 7.05494996778844, 7.741331306111289, 8.453613827012353, 9.191797530491641, 9.955882416549146, 10.745868485184873],
    g_port_w_per_k: [0.07560387378374933, 0.2748022522340945, 0.4423833607032144, 0.5836207577780461, 0.7098294089997703, 0.8258773502812233, 0.9344073607794409, 1.0370538264422924, 1.13491575020411, 1.2287766768315487, 1.3192199777537055, 1.4066947438777055, 1.4915560003471056, 1.5740905481755956, 1.654534275980776, 1.7330841630330174, 1.8099068453993519, 1.885144881645827, 1.9589214342603665, 2.0313438327482767, 2.1025063300899194, 2.1724922661956003, 2.241375787971247, 2.392372188132318, 2.6207827146944895, 2.8589128381316486, 3.106762558443794, 3.364331875630926, 3.6316207896930432, 3.908629300630146, 4.195357408442237, 4.4918051131293115],
    g_loop_block_w_per_k: [8.933381080694256, 12.059373001328881, 16.974119961248537, 21.02187395837909, 24.354251640797205, 27.17183273269746, 29.60728567133343, 31.748473298740084, 33.65604751058917, 35.37358052452336, 36.93344553079983, 38.36037394907429, 39.67370146776373, 40.88884190528057, 42.01828732101678, 43.07230659108939, 44.05944575577042, 44.986894306072564, 45.86075851911261, 46.68626891280987, 47.46794008630137, 50.6635489619979, 55.45903825567321, 59.36716787865576, 62.60457901840651, 65.3234768980779, 67.6338409688754, 69.61705289347995, 71.33457530333573, 72.83365727092144, 74.15118973868097, 75.31637418660927],
    g_ball_block_w_per_k: [0.44356272462810814, 0.8631598153412554, 1.3386181488960296, 1.7313669593858871, 2.0706471664216943, 2.3723843936675104, 2.6458392031472733, 2.8969376551696735, 3.129750536417811, 3.34722417619623, 3.55157733621289, 3.744533499525995, 3.927465123618757, 4.101487602791317, 4.267522916608381, 4.426344174969737, 4.578607666315402, 4.724876466667409, 4.865638191536064, 5.430558801853497, 6.17866184749917, 6.886534687334913, 7.555008443678394, 8.185289194898846, 8.778846020809585, 9.337321054427978, 9.862458494151882, 10.35604958471944, 10.81989079790601, 11.255752750803566, 11.665357735328644, 12.050364063044562],
    g_lng_w_per_k: [0.0, 3.3096682228248526, 9.942776739489462, 12.96264658390632, 14.136534000606629, 14.658585305173963, 14.930811085570172, 15.0900443468699, 15.191171939230621, 15.259425100268043, 15.307684378047224, 15.343080548790175, 15.369822002200275, 15.390523783739235, 15.406881138317255, 15.420032612236465, 15.430766148357852, 15.439641273518907, 15.447064292249626, 15.453336078719953, 15.458683321598944, 15.463279465193647, 15.467259058122599, 15.470727780930769, 15.473769579489431, 15.476451821691988, 15.47882908002316, 15.48094594339928, 15.482839133094563, 15.484539112987429, 15.486071327761085, 15.487457164214225],
    outer_w_per_k: [0.0, 0.21683159140672917, 0.10139433161277256, 0.0],
    outer_quarter_w_per_k125: [0.2037238720409924, 0.7855458029157932, 0.21064691787299047, 0.2564177663859325],
    outer_rad_w_per_k4: [4.8198179e-9, 1.735134444e-8, 3.85585432e-9, 5.78378148e-9],
    nominal_jacobian_per_s: [
        [-0.0006883357089114417, 0.000301960902861307, 0.0002635093844905335, 0.0, 0.0, 0.0],
        [0.011110428633751002, -0.018209857903568605, 0.006654548638886093, 0.0, 0.0, 0.0],
        [0.0008453905418370766, 0.0005997144604308335, -0.015554756092472921, 0.01251455018843467, 0.0011678886077642892, 0.0],
        [0.0, 0.0, 0.00047876209910518953, -0.0005387935174095315, 0.0, 0.0],
        [2.1780683253128878e-6, 0.0, 0.00023504275651297073, 0.0, -0.0003202049309092509, 0.0],
        [0.0, 0.0, 0.0, 0.0, 0.0, -0.00025111188000728236],
    ],
    phi_step_s: [
        [0.09999655899642731, 1.508880187026847e-6, 1.3171684615603562e-6, 5.494910940008905e-10, 5.1280140810234066e-11, 0.0],
        [5.5518101769134155e-5, 0.09990900717474191, 3.323580680953366e-5, 1.3868036116142207e-8, 1.294206317520539e-9, 0.0],
        [4.225775005101747e-6, 2.9952421313446664e-6, 0.0999222682738728, 6.253919729681677e-5, 5.8363542604988705e-6, 0.0],
        [6.74418206277902e-11, 4.7812917409883404e-11, 2.392526852610968e-6, 0.09999730707896234, 9.315190597044057e-11, 0.0],
        [1.092308552308241e-8, 2.3582895253354815e-11, 1.1745922478784808e-6, 4.900413227033551e-10, 0.09999839903816597, 0.0],
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.09999874445110943],
    ],
    rest_rate_per_s: [2.4154986597537136e-5, 2.4154986597537136e-5, 1.3610423581021226e-5, 1.3610423581021226e-5, 2.1664745628787115e-5, 5.177148895001672e-5],
    rest_mode: [0.9434130751947403, 1.0, 1.0, 0.9916372640256262, 1.0, 1.0],
};
