//! Building the model from its constants: every constant converted to the
//! build's number type (f32 or fixed point) with its range checked.

use super::*;

impl<N: Num> Model<N> {
    /// [`Model::init_in`] without the stability check.
    ///
    /// # Safety
    /// `dst` must be valid for writes of a `Model<N>`.
    pub(super) unsafe fn init_values_in<S: Word>(dst: *mut Self, c: &ModelConsts<S>) -> Result<(), ConfigError> {
        c.check_values()?;
        c.check_bounds()?;
        let max_row = N::MAX_ROW_SUM as f32;
        let mut phi = [[N::coef_from_f32(0.0).ok_or(ConfigError::CoefficientRange)?; N_NODES]; N_NODES];
        for (pr, dr) in phi.iter_mut().zip(c.phi.iter()) {
            if dr.iter().map(|x| x.to_f32().abs()).sum::<f32>() >= max_row {
                return Err(ConfigError::CoefficientRange);
            }
            for (o, x) in pr.iter_mut().zip(dr.iter()) {
                *o = x.to_coef::<N>().ok_or(ConfigError::CoefficientRange)?;
            }
        }
        let f = |x: S| x.to_n::<N>();
        let mut inv_n = [N::ZERO; TICKS_PER_STEP as usize + 1];
        let mut count = [N::ZERO; TICKS_PER_STEP as usize + 1];
        for (j, ((o, n), (x32, x64))) in inv_n.iter_mut().zip(count.iter_mut()).zip(INV_N_F32.iter().zip(INV_N_F64.iter())).enumerate() {
            *o = N::from_exact(*x32, *x64);
            *n = N::from_exact(j as f32, j as f64);
        }
        // a constant in both precisions, rounded at compile time
        macro_rules! exact {
            ($x:expr) => {
                N::from_exact(($x) as f32, $x)
            };
        }
        let k = Consts {
            p_case: f(c.p_case),
            k_lf: f(c.k_lf),
            k_lp: f(c.k_lp),
            k_mech: f(c.k_mech),
            k_q: f(c.k_q),
            k_a: f(c.k_a),
            k_dpq: f(c.k_dpq),
            r1: f(c.r1),
            r2: f(c.r2),
            w_dp: f(c.w_dp),
            w_dx: f(c.w_dx),
            k_act: f(c.k_act),
            k_lf_half: f(c.k_lf_half),
            k_cu: f(c.k_cu),
            k_sh: f(c.k_sh),
            k_hyd: f(c.k_hyd),
            fe1: f(c.fe1),
            fe2: f(c.fe2),
            fe15: f(c.fe15),
            inv_ticks: exact!(1.0 / TICKS_PER_STEP as f64),
            q_scale: f(c.q_scale),
            w_scale: f(c.w_scale),
            rc0: f(c.rc0),
            rc1: f(c.rc1),
            inv_v_case: f(c.inv_v_case),
            inv_v_loop: f(c.inv_v_loop),
            inv_n,
            count,
            v_port: f(c.v_port),
            v_ball: f(c.v_ball),
            inv_v_ring: f(c.inv_v_ring),
            inv_c: c.inv_c.map(f),
            f_out: f(c.f_out),
            f_case: f(c.f_case),
            k_m0: f(c.k_m0),
            k_mv: f(c.k_mv),
            alpha: f(c.alpha),
            g_case_slope: f(c.g_case_slope),
            t_film: exact!(crate::params::FILM_PROPERTY_C),
            alpha_t0: f(c.alpha_t0),
            lng_in: f(c.lng_in),
            k_mu: f(c.k_mu),
            t_mu: f(c.t_mu),
            use_mu: c.k_mu.to_f32() != 0.0,
            ga: c.ga.map(f),
            gb: c.gb.map(f),
            gr: c.gr.map(f),
            h: exact!(S_PER_STEP),
            inv_h: exact!(1.0 / S_PER_STEP),
            half: exact!(0.5),
            per_rad_t: exact!(1.0 / RAD_T_K),
            rad_offset: exact!(273.15 / RAD_T_K),
            one: exact!(1.0),
        };
        // SAFETY: the caller guarantees `dst` is valid for writes.
        unsafe { dst.write(Model {
            temp: [N::state(N::ZERO); N_NODES],
            links: [N::ZERO; 3],
            ring_rate: N::ZERO,
            lng_hist: 0,
            ambient_c: N::ZERO,
            sums: Sums::ZERO,
            phi,
            k,
            g_case: c.g_case.map(f),
            g_port: c.g_port.map(f),
            g_loop: c.g_loop.map(f),
            g_ball: c.g_ball.map(f),
            g_lng: c.g_lng.map(f),
            last_total_kw: N::ZERO,
            last_lng_kw: N::ZERO,
            last_heat_kw: N::ZERO,
            last_outer_kw: N::ZERO,
            last_losses_kw: [N::ZERO; N_LOSSES],
            last_mech_pair_kw: (N::ZERO, N::ZERO),
            loss_max: false,
            outer_g: [N::ZERO; 4],
            outer_phase: 0,
        }) };
        Ok(())
    }
}
