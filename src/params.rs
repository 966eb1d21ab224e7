//! SI parameters of the reduced-order model (design side, `f64`).
//!
//! Everything is plain SI so that the reduction tool in `host-tests`
//! (`eha_sim::reduce`) can derive every field from the reference rig and
//! regenerate [`DEFAULT`] with plain literals. The firmware never steps with these
//! numbers directly: [`crate::model::Model::new`] converts them once into model units
//! of the firmware's number type and builds the exact-ZOH matrix.
//!
//! Node order (fixed): `0 pump housing, 1 drain (case) oil, 2 loop oil, 3 main
//! valve block, 4 ball/needle-valve block, 5 actuator body` ([`NODE_PUMP`] ...):
//! every state is a contract node, saved in the thermal record and reported.

mod read;

/// Number of thermal states of the reduced model, all of them contract nodes: the
/// thermal record saves them and the model reports them
/// ([`crate::model::Model::temperatures_c`]).
pub const N_NODES: usize = 6;
/// The model's states: the same as [`N_NODES`].
pub const N_STATES: usize = N_NODES;
/// States advanced by the exact-ZOH matrix `Phi`: [`PHI_STATES`], the fast and
/// strongly coupled ones (pump housing, case oil, loop oil). The others (main and
/// ball-valve blocks, actuator: time constants of minutes against the 100 ms step)
/// by explicit Euler, whose error there is a thousandth of the step's change.
pub const N_PHI: usize = 3;
/// The states of `Phi`, in its row order.
pub const PHI_STATES: [usize; N_PHI] = [NODE_PUMP, NODE_DRAIN, NODE_LOOP];
/// The states advanced by explicit Euler.
pub const EULER_STATES: [usize; N_STATES - N_PHI] = [NODE_MAIN_BLOCK, NODE_BALL_BLOCK, NODE_ACTUATOR];
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
pub const OUTER_NODES: [usize; N_OUTER] = [NODE_PUMP, NODE_MAIN_BLOCK, NODE_BALL_BLOCK, NODE_ACTUATOR];
/// Number of outer surfaces.
pub const N_OUTER: usize = 4;

/// Points of the tables over the oil temperature (viscosity and film factors),
/// uniform from [`TEMP_TABLE_MIN_C`] in steps of [`TEMP_TABLE_STEP_K`]:
/// −20 … 177.5 degC. Outside it a table holds its end value (below −6 degC the oil
/// is past the model's validity anyway, docs/reduction.md).
pub const N_TEMP: usize = 80;
/// First point of the temperature tables, degC.
pub const TEMP_TABLE_MIN_C: f64 = -20.0;
/// Step of the temperature tables, K.
pub const TEMP_TABLE_STEP_K: f64 = 2.5;
/// Points of the coarse temperature grid of the ducts' transitional films: every
/// [`COARSE_STRIDE`]-th point of the temperature tables (−20 … 180 degC in 20 K).
pub const N_COARSE: usize = 11;
/// Fine temperature-table steps per coarse step.
pub const COARSE_STRIDE: usize = 8;
/// The ducts with a transitional film (eqs. 13-14 blended), in table order: one port
/// passage, the loop oil <-> main block, the ball-valve oil <-> its block.
pub const N_DUCTS: usize = 3;
/// Reynolds numbers at which the ducts' films are tabulated over temperature: the
/// end of the laminar range, the start of the turbulent one and two turbulent points
/// (linear between them; held beyond the last).
pub const DUCT_RE: [f64; N_RE] = [2300.0, 1e4, 3e4, 1e5];
/// Number of [`DUCT_RE`].
pub const N_RE: usize = 4;

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
    /// Slope of the oil density, kg/(m^3 K) (`rho = rho40 + slope (T - 40)`, negative).
    pub rho_slope_kg_per_m3_k: f64,
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
    /// viscosity, W per (rad/s)^2: heat `C_v mu D w^2`, split like the pressure
    /// term, scaled by [`Self::visc_ratio`] at the case oil.
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
    /// Pump leakage flow conductance of the gaps (eqs. 5-7), m^3/(s Pa), at
    /// [`FILM_PROPERTY_C`]: each port leaks `K (p_port - p_case)` into the case;
    /// scaled by [`Self::leak_ratio`] at the case oil.
    pub k_leak_m3_per_s_pa: f64,
    /// Case (accumulator) pressure, Pa gauge.
    pub case_pressure_pa: f64,
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
    /// Case oil <-> pump housing conductance over shaft speed at the 40 degC
    /// viscosity (Taylor-Couette film of the case gap): read at `|w| tc_speed_ratio(T)`
    /// (its Taylor number is `(w / nu)^2`), W/K.
    pub g_case_w_per_k: [f64; N_TABLE],
    /// Leakage conductance at the case oil over its value at [`FILM_PROPERTY_C`]
    /// (`mu(40) / mu(T)`, the Walther line), on the temperature grid.
    pub leak_ratio: [f64; N_TEMP],
    /// Viscous friction at the case oil over its value at [`FILM_PROPERTY_C`]
    /// (`mu(T) / mu(40)`), on the temperature grid.
    pub visc_ratio: [f64; N_TEMP],
    /// Speed factor of the case gap's Taylor number, `nu(40) / nu(T)`, on the
    /// temperature grid.
    pub tc_speed_ratio: [f64; N_TEMP],
    /// Reynolds number of each duct ([`N_DUCTS`] order) per unit flow at the 40 degC
    /// viscosity, in units of 1e4 per m^3/s: `Re = this * 1e4 * q * nu(40)/nu(T)`.
    pub re_per_flow: [f64; N_DUCTS],
    /// Conductance of the block wall behind the loop's and the ball-valve passage's
    /// films (eq. 18), W/K: `[loop, ball]`; a transitional film is blended first and
    /// put in series with it after.
    pub duct_wall_w_per_k: [f64; 2],
    /// Port passage <-> housing at the end of the laminar range (Re = 2300) over the
    /// coarse temperature grid, W/K (the laminar table's law at that flow; for the
    /// loop and the ball-valve passage the film alone, without the wall).
    pub g_port_re2300_w_per_k: [f64; N_COARSE],
    /// Port passage <-> housing at the start of the turbulent range (Re = 1e4), W/K.
    pub g_port_re1e4_w_per_k: [f64; N_COARSE],
    /// Port passage <-> housing at Re = 3e4, W/K.
    pub g_port_re3e4_w_per_k: [f64; N_COARSE],
    /// Port passage <-> housing at Re = 1e5, W/K.
    pub g_port_re1e5_w_per_k: [f64; N_COARSE],
    /// Loop oil <-> main block at Re = 2300, W/K.
    pub g_loop_re2300_w_per_k: [f64; N_COARSE],
    /// Loop oil <-> main block at Re = 1e4, W/K.
    pub g_loop_re1e4_w_per_k: [f64; N_COARSE],
    /// Loop oil <-> main block at Re = 3e4, W/K.
    pub g_loop_re3e4_w_per_k: [f64; N_COARSE],
    /// Loop oil <-> main block at Re = 1e5, W/K.
    pub g_loop_re1e5_w_per_k: [f64; N_COARSE],
    /// Ball-valve oil <-> its block at Re = 2300, W/K.
    pub g_ball_re2300_w_per_k: [f64; N_COARSE],
    /// Ball-valve oil <-> its block at Re = 1e4, W/K.
    pub g_ball_re1e4_w_per_k: [f64; N_COARSE],
    /// Ball-valve oil <-> its block at Re = 3e4, W/K.
    pub g_ball_re3e4_w_per_k: [f64; N_COARSE],
    /// Ball-valve oil <-> its block at Re = 1e5, W/K.
    pub g_ball_re1e5_w_per_k: [f64; N_COARSE],
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
    pub outer_w_per_k: [f64; N_OUTER],
    /// Outer surfaces: free-convection part `A c1` of `h = c0 + c1 |dT|^(1/4)`, W/K^1.25.
    pub outer_quarter_w_per_k125: [f64; N_OUTER],
    /// Outer surfaces: radiation `eps sigma A` (eq. 19, linearised about the mean of
    /// wall and air: `4 eps sigma A T_m^3 dT`), W/K^4.
    pub outer_rad_w_per_k4: [f64; N_OUTER],
    /// Jacobian of the model's right-hand side at the nominal operating point
    /// (500 rpm, 30 bar, nodes at 40 degC, air 20 degC) over the [`PHI_STATES`]
    /// (rows and columns in that order), 1/s: the linear part whose zero-order hold is exact (exponential Euler).
    pub nominal_jacobian_per_s: [[f64; N_PHI]; N_PHI],
    /// The model step's exact-ZOH matrix `Phi = h phi1(h A)` of
    /// [`Self::nominal_jacobian_per_s`] at `h` = [`crate::params::S_PER_STEP`], s:
    /// computed on the host by `eha_sim::reduce` (`crate::model::etd_matrix`, the
    /// 2 N_PHI x 2 N_PHI matrix exponential), so that the firmware does no matrix
    /// exponential at boot.
    pub phi_step_s: [[f64; N_PHI]; N_PHI],
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
    /// Commissioning safety margin on the drain-oil estimate, K (≥ 0, at most
    /// 10 K: `model::bounds`): the guard adds it to the model's case-oil
    /// temperature for every decision and report (valve at 40 °C, alarm,
    /// the reported drain temperature), so that the estimate errs on the hot
    /// side on a machine whose model under-predicts by up to this much on
    /// held-out validation logs. The model's own state stays physical (the
    /// margin never feeds back). Set by commissioning; 0 for the paper rig
    /// (the reduction of a rig file has no validation logs).
    pub drain_margin_k: f64,
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
    loop_oil_m3: 0.001674741,
    port_oil_m3: 5e-5,
    ball_oil_m3: 5e-5,
    rho_kg_per_m3: 857.83,
    rho_slope_kg_per_m3_k: -0.5668000000000575,
    cp20_j_per_kg_k: 1880.0,
    cp_slope_j_per_kg_k2: 3.7,
    displacement_m3_per_rad: 3.023943918746011e-6,
    eta_m: 0.44359,
    no_load_torque_nm: 0.3,
    viscous_w_s2_per_rad2: 0.005966268567181156,
    mech_to_outlet: 0.6,
    mech_to_case: 0.15,
    case_film_slope_per_k: -0.0005335365853657948,
    expansion_per_k: 0.00065,
    k_leak_m3_per_s_pa: 3.357993172582738e-13,
    case_pressure_pa: 500000.0,
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
    drain_margin_k: 0.0,
    g_case_w_per_k: [0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.8746666666666667, 0.9909649520295366, 1.1259831778645393, 1.266376008477383, 1.41191902241602, 1.5624128470825693, 1.694181016281733, 1.796142991324628, 1.8978891486780984, 1.9994319105917768, 2.1007823674938515, 2.2019504803423966, 2.3029452440391234, 2.403774820832143, 2.504446650287594, 2.604967540752545, 2.7053437460414993, 2.8055810302112434, 2.9056847226476346, 3.0056597652081094, 3.1055107528003925, 3.2052419684999256],
    leak_ratio: [0.009793595560862883, 0.013232053963938615, 0.017640064644754573, 0.023220709389381113, 0.03020287710619231, 0.03884147545389507, 0.049417180120621226, 0.06223571770029516, 0.07762669435778467, 0.09594199750709445, 0.117553810858622, 0.1428522939139741, 0.17224298498372506, 0.20614399194776817, 0.24498303731387053, 0.28919442384815697, 0.33921598445380247, 0.3954860754422882, 0.45844066629893604, 0.5285105719282248, 0.6061188655961373, 0.6916785027557626, 0.7855901779852433, 0.8882404296659193, 1.0, 1.121222451669108, 1.2522430369670374, 1.3933778106510044, 1.5449229740505959, 1.7071544351233592, 1.8803275670958557, 2.0646771470010177, 2.260417454736315, 2.4677425131247976, 2.686826449774355, 2.9178239622087685, 3.1608708687032956, 3.416084728422263, 3.6835655157620417, 3.9633963351859345, 4.255644164258201, 4.560360613996651, 4.877582697037089, 5.2073335954189774, 5.549623421035552, 5.904449962938757, 6.271799416736259, 6.651647092268677, 7.043958096601944, 7.448687990120717, 7.865783414166584, 8.295182689233172, 8.736816383216258, 9.190607849630014, 9.656473736042454, 10.134324463264477, 10.624064676055546, 11.125593666285075, 11.638805769626993, 12.163590736965137, 12.69983408175332, 13.247417404617618, 13.806218696507958, 14.376112621705865, 14.956970781979773, 15.548661963156288, 16.15105236533236, 16.764005817915812, 17.387383980626513, 18.021046531538744, 18.66485134318716, 19.31865464770056, 19.982311191869446, 20.655674382992846, 21.338596426291527, 22.03092845462182, 22.73252065116139, 23.44322236569504, 24.16288222506898, 24.89134823833828],
    visc_ratio: [102.10754505691402, 75.57405696238128, 56.68913465673487, 43.065006466051486, 33.10942849861731, 25.74567490843654, 20.235877432891225, 16.067943569248136, 12.882166479883303, 10.422964144831932, 8.506742509629621, 7.000237606280244, 5.805751683265871, 4.850978146641186, 4.081915266316202, 3.4578813335801217, 2.9479742872676717, 2.5285340296283736, 2.1813073610444684, 1.892109738413722, 1.6498414036601021, 1.4457583921082309, 1.2729283384940488, 1.1258213053599857, 1.0, 0.8918836743871386, 0.7985670277089533, 0.7176804398318837, 0.6472814611450333, 0.5857700858374537, 0.5318222300726508, 0.4843372250487292, 0.44239615912745334, 0.4052286633153402, 0.372186301829797, 0.3427211555432591, 0.31636850777464265, 0.29273278606934766, 0.27147609991487387, 0.25230885720973123, 0.23498205239965347, 0.21928090443786433, 0.20501958902869136, 0.19203686141401144, 0.18019240660718588, 0.16936378600493399, 0.15944387464489154, 0.1503387035013203, 0.1419656372576105, 0.13425183083602266, 0.1271329182798195, 0.12055189589711646, 0.11445816830041619, 0.10880673143292226, 0.10355747111572773, 0.09867455927870294, 0.09412593301072367, 0.08988284400772188, 0.08591946801016584, 0.08221256548537113, 0.07874118618894127, 0.07548641138546994, 0.07243112846335924, 0.06955983347613344, 0.0668584578105083, 0.06431421574213746, 0.06191547011180913, 0.059651613752799634, 0.05751296463655641, 0.055490672988935126, 0.05357663887127658, 0.05176343892658317, 0.05004426116669065, 0.04841284682640838, 0.046863438439085366, 0.045390733398265486, 0.043989842364837384, 0.042656251960623, 0.04138579125972399, 0.04017460164973205],
    tc_speed_ratio: [0.010181855003682353, 0.013734771134868432, 0.018281114007956584, 0.024026205407589634, 0.031200684990259662, 0.04006051540778479, 0.050886509237295346, 0.06398337889619925, 0.07967832744881634, 0.09831921345549131, 0.12027233609067654, 0.14591989717591333, 0.1756572042540505, 0.20988968328811516, 0.24902977109415048, 0.2934937564517446, 0.3436986353284144, 0.4000590402282156, 0.4629842967908442, 0.5328756528907832, 0.6101237170587801, 0.6951061344720872, 0.7881855203775707, 0.8897076629042493, 1.0, 1.119370368839159, 1.2481060205806151, 1.3864728888447289, 1.5347150967125232, 1.6930546843885412, 1.8616915378412844, 2.0408034976519587, 2.2305466268719476, 2.4310556168051534, 2.642444310197396, 2.864806322234709, 3.0982157409373854, 3.3427278899084936, 3.5983801378880016, 3.865192741112077, 4.143169706041466, 4.432299661557863, 4.7325567312039665, 5.043901397443312, 5.366281351217351, 5.69963232127646, 6.0438788788472415, 6.398935214176131, 6.7647058823529225, 7.141086516576976, 7.527964507687766, 7.925219649344883, 8.332724748719345, 8.750346202957775, 9.177944542007314, 9.615374938652584, 10.062487686825673, 10.519128649406257, 10.985139676847435, 11.460358998042755, 11.944621584896833, 12.437759492086352, 12.939602173499708, 13.449976776825958, 13.968708417732062, 14.49562043502893, 15.030534628169532, 15.573271478371348, 16.123650354588598, 16.681489705496794, 17.24660723858412, 17.818820087377173, 18.39794496776188, 18.98379832429317, 19.57619646732209, 20.17495570171022, 20.779892447834186, 21.390823355534447, 22.00756541160031, 22.6299360413355],
    re_per_flow: [230.65933781434077, 276.79120537720894, 345.9890067215112],
    duct_wall_w_per_k: [90.0, 20.000000000000004],
    g_port_re2300_w_per_k: [182.76586348988135, 28.476650875872128, 7.0175369915254535, 2.272547436142525, 1.7359468595565273, 1.4095423651593038, 1.1948972080398605, 1.0450100411659393, 0.935330628779396, 0.8520678217845593, 0.7869923107926399],
    g_port_re1e4_w_per_k: [48.731847000336316, 24.600429680199714, 15.126519695931897, 10.59157666913066, 8.093169432490145, 6.566294691089503, 5.556766964017251, 4.847466500957033, 4.324843847672852, 3.9250274270070187, 3.6098496471106487],
    g_port_re3e4_w_per_k: [136.05522410783462, 68.65514091487351, 42.179540058949556, 29.493919781575514, 22.495787282719846, 18.212431173724088, 15.376057130509682, 13.380435742145147, 11.908347163605569, 10.781215697628287, 9.892226702974412],
    g_port_re1e5_w_per_k: [405.1527301019578, 204.35641277485942, 125.43393848789101, 87.57918272912589, 66.66703748101081, 53.84745704762383, 45.34585267626859, 39.356635731104745, 34.93434870814671, 31.54624312235815, 28.873283858573615],
    g_loop_re2300_w_per_k: [15451.413104734955, 2407.476364133904, 548.2006236245651, 87.20399030280635, 66.3884742068077, 53.73874285024751, 45.43190754157737, 39.64211469791286, 35.41531565067272, 32.21533348689566, 29.72206106378332],
    g_loop_re1e4_w_per_k: [4119.89353471702, 2079.7724163833977, 1278.8280053823814, 895.4343191898697, 684.2136810463074, 555.1284572628579, 469.78084554902665, 409.815082463679, 365.6314567056138, 331.83012989435025, 305.18433299540317],
    g_loop_re3e4_w_per_k: [11502.39674195962, 5804.25098967255, 3565.947631432983, 2493.478431481097, 1901.8414915364738, 1539.7174961085866, 1299.9244284951722, 1131.2103706100017, 1006.7568850441021, 911.4668042182333, 836.3097921828835],
    g_loop_re1e5_w_per_k: [34252.46971058753, 17276.723859107897, 10604.45076515955, 7404.129556161418, 5636.172515580174, 4552.378040379359, 3833.634404743578, 3327.2933220789337, 2953.423812999541, 2666.9861924896395, 2441.008556358756],
    g_ball_re2300_w_per_k: [861.6927086702757, 134.2598774111149, 31.279875236652728, 6.510869918776328, 4.963517789837473, 4.022593578437068, 3.404131277335188, 2.972530763975067, 2.6569554099971517, 2.417606852554087, 2.2307330896703546],
    g_ball_re1e4_w_per_k: [229.75777006930008, 115.98451965160078, 71.31753972351336, 49.936482748143966, 38.157153402971296, 30.95834282316851, 26.198686588639816, 22.854522500200634, 20.390494912544334, 18.505466232046402, 17.01948635765578],
    g_ball_re3e4_w_per_k: [641.4643979547756, 323.6908315887564, 198.86537578651766, 139.05603125551232, 106.06168738064376, 85.86679618333726, 72.49404273020241, 63.08521568348548, 56.14470737179753, 50.83058061201978, 46.63923262091215],
    g_ball_re1e5_w_per_k: [1910.1879681488856, 963.4864383077681, 591.3878453609342, 412.912683736302, 314.31744970917657, 253.87651847218277, 213.7937023548189, 185.5561284788972, 164.70621476653102, 148.73219301141984, 136.1298970235626],
    g_port_w_per_k: [0.07560387378374933, 0.2748022522340945, 0.4423833607032144, 0.5836207577780461, 0.7098294089997703, 0.8258773502812233, 0.9344073607794409, 1.0370538264422924, 1.13491575020411, 1.2287766768315487, 1.3192199777537055, 1.4066947438777055, 1.4915560003471056, 1.5740905481755956, 1.654534275980776, 1.7330841630330174, 1.8099068453993519, 1.885144881645827, 1.9589214342603665, 2.0313438327482767, 2.1025063300899194, 2.1724922661956003, 2.241375787971247, 2.3940293040830216, 2.625598633151265, 2.8670219762224147, 3.118299333296468, 3.379430704373425, 3.6504160894532873, 3.931255488536051, 4.221948901621722, 4.522496328710296],
    g_loop_block_w_per_k: [7.739065756311008, 10.501276361074016, 14.902440317989587, 18.58187652541279, 21.64886055507298, 24.269163158494546, 26.554406874416717, 28.579291333901722, 30.39580865470424, 32.04157996087655, 33.54474072953957, 34.926915974259565, 36.20510914480882, 37.39294766915762, 38.50153191650342, 39.54003069008981, 40.51610945060784, 41.43624500821903, 42.30596122673184, 43.130008558544, 43.912502854009574, 47.16602485993483, 52.1145036871813, 56.20083323731119, 59.622925382047214, 62.52326619447232, 65.0069506990573, 67.15311971652311, 69.02245086259484, 70.66220402135673, 72.10970352287801, 73.39479354580159],
    g_ball_block_w_per_k: [0.44356272462810814, 0.8631598153412554, 1.3386181488960296, 1.7313669593858871, 2.0706471664216943, 2.3723843936675104, 2.6458392031472733, 2.8969376551696735, 3.129750536417811, 3.34722417619623, 3.55157733621289, 3.744533499525995, 3.927465123618757, 4.101487602791317, 4.267522916608381, 4.426344174969737, 4.578607666315402, 4.724876466667409, 4.865638191536064, 5.436804115536091, 6.193122277467843, 6.907908417439102, 7.582144285381395, 8.217177181136199, 8.814606099235066, 9.376190935013017, 9.903781391674087, 10.399262351420411, 10.864512756565988, 11.301375403172534, 11.71163542501122, 12.097005606435383],
    g_lng_w_per_k: [0.0, 3.3096682228248526, 9.942776739489462, 12.96264658390632, 14.136534000606629, 14.658585305173963, 14.930811085570172, 15.0900443468699, 15.191171939230621, 15.259425100268043, 15.307684378047224, 15.343080548790175, 15.369822002200275, 15.390523783739235, 15.406881138317255, 15.420032612236465, 15.430766148357852, 15.439641273518907, 15.447064292249626, 15.453336078719953, 15.458683321598944, 15.463279465193647, 15.467259058122599, 15.470727780930769, 15.473769579489431, 15.476451821691988, 15.47882908002316, 15.48094594339928, 15.482839133094563, 15.484539112987429, 15.486071327761085, 15.487457164214225],
    outer_w_per_k: [0.0, 2.2273470381326628, 0.10347555432347269, 0.0],
    outer_quarter_w_per_k125: [0.20636535005539558, 0.7753467279600061, 0.20862972461030688, 0.258650733318923],
    outer_rad_w_per_k4: [4.8198179e-9, 1.735134444e-8, 3.85585432e-9, 5.78378148e-9],
    nominal_jacobian_per_s: [
        [-0.0004823829718323333, 7.40359092546005e-5, 0.00026369136373367397],
        [0.003540221588587175, -0.010162020079964446, 0.006662330932038774],
        [0.0008479434296390573, 0.0003798946085244864, -0.014248358023296416],
    ],
    phi_step_s: [
        [0.09999758820484932, 3.7006492139474624e-7, 1.3178918153950377e-6],
        [1.769576995608693e-5, 0.09994920757146787, 3.328471774940955e-5],
        [4.237860107581388e-6, 1.8979386558555626e-6, 0.09992879249245061],
    ],
    rest_rate_per_s: [2.4189268114481766e-5, 2.4189268114481766e-5, 3.988500390002124e-5, 3.988500390002124e-5, 2.178956514958621e-5, 5.184342444155369e-5],
    rest_mode: [0.9846710908800222, 1.0, 1.0, 0.9809577190382728, 1.0, 1.0],
};
