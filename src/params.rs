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

/// Oil temperature at which the reduction evaluates the film properties
/// (conductance tables), degC.
pub const FILM_PROPERTY_C: f64 = 40.0;

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
    /// Relative slope of the case-oil film conductance with the case-oil
    /// temperature about [`FILM_PROPERTY_C`], 1/K (the laminar Taylor-Couette film
    /// scales with the oil's conductivity k(T)).
    pub case_film_slope_per_k: f64,
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
    /// Motor pole pairs: the drive's electrical frequency is pole pairs x
    /// rev/s (the second speed source of the speed check, `crate::speedcheck`).
    pub pole_pairs: f64,
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
            self.pole_pairs,
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
            self.case_film_slope_per_k,
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
    loop_oil_m3: 0.001432525,
    port_oil_m3: 5e-5,
    ball_oil_m3: 5e-5,
    rho_kg_per_m3: 857.83,
    cp20_j_per_kg_k: 1880.0,
    cp_slope_j_per_kg_k2: 3.7,
    displacement_m3_per_rad: 3.023943918746011e-6,
    eta_m: 0.276656,
    no_load_torque_nm: 0.3,
    viscous_w_s2_per_rad2: 0.005966268567181156,
    mech_to_outlet: 0.6,
    mech_to_case: 0.15,
    case_film_slope_per_k: -0.0005335365853657948,
    expansion_per_k: 0.00065,
    k_leak_m3_per_s_pa: 3.357993172582738e-13,
    case_pressure_pa: 500000.0,
    k_mu_per_k: 0.0,
    t_mu_ref_c: 40.0,
    line_r1_pa_s_per_m3: 588776503.3402457,
    line_r2_pa_s2_per_m6: 1018550987858.2805,
    ram_area_m2: 0.00152681,
    act_leak_m3_per_s_pa: 2e-14,
    act_friction_n_s_per_m: 2000.0,
    phases: 3.0,
    r_ohm: 0.074,
    torque_constant_nm_per_a: 0.75,
    pole_pairs: 4.0,
    k_fe1_w_s_per_rad: 0.37433242615213785,
    k_fe2_w_s2_per_rad2: 0.0015887161595118564,
    k_fe15_w_per_rad15: 0.008414188516295527,
    speed_table_max_rad_s: 628.3185307179587,
    flow_table_max_m3_per_s: 0.0018999999999999998,
    lng_inlet_c: -162.0,
    g_case_w_per_k: [0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.9909649520295366, 1.1259831778645393, 1.266376008477383, 1.41191902241602, 1.5624128470825693, 1.694181016281733, 1.796142991324628, 1.8978891486780984, 1.9994319105917768, 2.1007823674938515, 2.2019504803423966, 2.3029452440391234, 2.403774820832143, 2.504446650287594, 2.604967540752545, 2.7053437460414993, 2.8055810302112434, 2.9056847226476346, 3.0056597652081094, 3.1055107528003925, 3.2052419684999256],
    g_port_w_per_k: [0.07560387378374933, 0.2748022522340945, 0.4423833607032144, 0.5836207577780461, 0.7098294089997703, 0.8258773502812233, 0.9344073607794409, 1.0370538264422924, 1.13491575020411, 1.2287766768315487, 1.3192199777537055, 1.4066947438777055, 1.4915560003471056, 1.5740905481755956, 1.654534275980776, 1.7330841630330174, 1.8099068453993519, 1.885144881645827, 1.9589214342603665, 2.0313438327482767, 2.1025063300899194, 2.1724922661956003, 2.241375787971247, 2.3940293040830216, 2.625598633151265, 2.8670219762224147, 3.118299333296468, 3.379430704373425, 3.6504160894532873, 3.931255488536051, 4.221948901621722, 4.522496328710296],
    g_loop_block_w_per_k: [6.8683196503930155, 9.355089308383494, 13.35658558346415, 16.73942383552595, 19.58570328683085, 22.03679883559714, 24.18919385343568, 26.107938216255462, 27.838570717073328, 29.41421055043053, 30.85974190323095, 32.194374320861456, 33.433274319847875, 34.58864478342061, 35.67046288046988, 36.68699912948892, 37.64519167161809, 38.55092203585155, 39.40922221297289, 40.22443277475156, 41.00032542228281, 44.24522251691708, 49.23952743482819, 53.41828111859969, 56.95645770332692, 59.983216232171465, 62.595866879303365, 64.8690373369517, 66.86085703932562, 68.61723107342927, 70.17485718572195, 71.56339600920737],
    g_ball_block_w_per_k: [0.44356272462810814, 0.8631598153412554, 1.3386181488960296, 1.7313669593858871, 2.0706471664216943, 2.3723843936675104, 2.6458392031472733, 2.8969376551696735, 3.129750536417811, 3.34722417619623, 3.55157733621289, 3.744533499525995, 3.927465123618757, 4.101487602791317, 4.267522916608381, 4.426344174969737, 4.578607666315402, 4.724876466667409, 4.865638191536064, 5.436804115536091, 6.193122277467843, 6.907908417439102, 7.582144285381395, 8.217177181136199, 8.814606099235066, 9.376190935013017, 9.903781391674087, 10.399262351420411, 10.864512756565988, 11.301375403172534, 11.71163542501122, 12.097005606435383],
    g_lng_w_per_k: [0.0, 3.3096682228248526, 9.942776739489462, 12.96264658390632, 14.136534000606629, 14.658585305173963, 14.930811085570172, 15.0900443468699, 15.191171939230621, 15.259425100268043, 15.307684378047224, 15.343080548790175, 15.369822002200275, 15.390523783739235, 15.406881138317255, 15.420032612236465, 15.430766148357852, 15.439641273518907, 15.447064292249626, 15.453336078719953, 15.458683321598944, 15.463279465193647, 15.467259058122599, 15.470727780930769, 15.473769579489431, 15.476451821691988, 15.47882908002316, 15.48094594339928, 15.482839133094563, 15.484539112987429, 15.486071327761085, 15.487457164214225],
    outer_w_per_k: [0.0, 2.2168315914067294, 0.10139433161277256, 0.0],
    outer_quarter_w_per_k125: [0.2037238720409924, 0.7855458029157932, 0.21064691787299047, 0.2564177663859325],
    outer_rad_w_per_k4: [4.8198179e-9, 1.735134444e-8, 3.85585432e-9, 5.78378148e-9],
    nominal_jacobian_per_s: [
        [-0.00048144726981819326, 9.507246376810191e-5, 0.00026365975745246736, 0.0, 0.0, 0.0],
        [0.0035402363248539237, -0.010396471399826135, 0.006662334881753218, 0.0, 0.0, 0.0],
        [0.0009913149277368527, 0.0007032323706537835, -0.01569195683179536, 0.01219758275147892, 0.0013694801918082145, 0.0],
        [0.0, 0.0, 0.00039794583019696003, -0.00048515116154476505, 0.0, 0.0],
        [2.1780683252153096e-6, 0.0, 0.000235202381232831, 0.0, -0.0003202049309092617, 0.0],
        [0.0, 0.0, 0.0, 0.0, 0.0, -0.00025111188000728236],
    ],
    phi_step_s: [
        [0.09999759290191179, 4.752208825535814e-7, 1.3176938624269953e-6, 5.358109734754191e-10, 6.015827526989888e-11, 0.0],
        [1.7695864987517125e-5, 0.09994803648897767, 3.328287621717924e-5, 1.3535116725180524e-8, 1.5196577119102895e-9, 0.0],
        [4.954318730835596e-6, 3.513121392413366e-6, 0.0999215829249035, 6.095504024532915e-5, 6.843747727578729e-6, 0.0],
        [6.57250315779913e-11, 4.6610581332782994e-11, 1.9886566534812446e-6, 0.09999757509207974, 9.079237301354642e-11, 0.0],
        [1.0928896988825797e-8, 2.7583391974164833e-11, 1.1753845749216565e-6, 4.77952973537982e-10, 0.09999839904609611, 0.0],
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.09999874445110943],
    ],
    rest_rate_per_s: [2.415966132218103e-5, 2.415966132218103e-5, 4.008003632381229e-5, 4.008003632381229e-5, 2.1664745628787115e-5, 5.177148895001672e-5],
    rest_mode: [0.9848793419641604, 1.0, 1.0, 0.9818205772094497, 1.0, 1.0],
};
