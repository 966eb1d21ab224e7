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
        let mut phi = [[N::coef_from_f32(0.0).ok_or(ConfigError::CoefficientRange)?; N_PHI]; N_PHI];
        for (pr, dr) in phi.iter_mut().zip(c.phi.iter()) {
            if dr.iter().map(|x| x.to_f32().abs()).sum::<f32>() >= max_row {
                return Err(ConfigError::CoefficientRange);
            }
            for (o, x) in pr.iter_mut().zip(dr.iter()) {
                *o = x.to_coef::<N>().ok_or(ConfigError::CoefficientRange)?;
            }
        }
        let k = consts_of::<N, S>(c);
        // Written field by field in place: the tables are most of the model
        // (2.9 KiB in f32), and a `Model` value built first would take as much boot
        // stack.
        // SAFETY: the caller guarantees `dst` is valid for writes of a `Model<N>`;
        // every field is written below (the arrays element by element through
        // pointers into their own field), none is read.
        unsafe {
            use core::ptr::addr_of_mut;
            addr_of_mut!((*dst).temp).write([N::state(N::ZERO); N_STATES]);
            addr_of_mut!((*dst).links).write([N::ZERO; 3]);
            addr_of_mut!((*dst).ring_rate).write(N::ZERO);
            addr_of_mut!((*dst).lng_hist).write(0);
            addr_of_mut!((*dst).ambient_c).write(N::ZERO);
            addr_of_mut!((*dst).sums).write(Sums::ZERO);
            addr_of_mut!((*dst).phi).write(phi);
            addr_of_mut!((*dst).k_mv_t).write(k.k_mv);
            addr_of_mut!((*dst).k_lf_t).write(k.k_lf);
            addr_of_mut!((*dst).k).write(k);
            let tables: [(*mut [N; N_TABLE], &[S; N_TABLE]); 5] = [
                (addr_of_mut!((*dst).g_case), &c.g_case),
                (addr_of_mut!((*dst).g_port), &c.g_port),
                (addr_of_mut!((*dst).g_loop), &c.g_loop),
                (addr_of_mut!((*dst).g_ball), &c.g_ball),
                (addr_of_mut!((*dst).g_lng), &c.g_lng),
            ];
            for (d, src) in tables {
                copy_words::<N, S>(d.cast::<N>(), src, 1);
            }
            let gt = addr_of_mut!((*dst).g_trans).cast::<N>();
            for (j, row) in c.g_trans.iter().enumerate() {
                copy_words::<N, S>(gt.add(j * row.len()), row, 1);
            }
            let tt = addr_of_mut!((*dst).t_tab).cast::<N>();
            for (m, tab) in [&c.leak_ratio, &c.visc_ratio, &c.tc_speed].into_iter().enumerate() {
                copy_words::<N, S>(tt.add(m), tab, 3);
            }
            addr_of_mut!((*dst).last_total_kw).write(N::ZERO);
            addr_of_mut!((*dst).last_lng_kw).write(N::ZERO);
            addr_of_mut!((*dst).last_heat_kw).write(N::ZERO);
            addr_of_mut!((*dst).last_outer_kw).write(N::ZERO);
            addr_of_mut!((*dst).last_losses_kw).write([N::ZERO; N_LOSSES]);
            addr_of_mut!((*dst).last_mech_pair_kw).write((N::ZERO, N::ZERO));
            addr_of_mut!((*dst).loss_max).write(false);
            addr_of_mut!((*dst).outer_g).write([N::ZERO; N_OUTER]);
            let one = N::from_exact(1.0, 1.0);
            addr_of_mut!((*dst).slow).write(Slow { case: [one; 3], duct: [one; 2] });
            addr_of_mut!((*dst).outer_phase).write(0);
            // every field is written: the oil's factors at the start (0 degC, like
            // the states)
            (*dst).refresh_slow(N::ZERO, N::ZERO);
        }
        Ok(())
    }
}

/// Converts `src` into the number type, writing word `j` at `dst + j * stride`. One
/// rolled copy for every table (unrolled per table, the init grew by 5 KiB of flash).
///
/// # Safety
/// `dst + j * stride` must be valid for writes for every `j < src.len()`.
#[inline(never)]
unsafe fn copy_words<N: Num, S: Word>(dst: *mut N, src: &[S], stride: usize) {
    for j in 0..core::hint::black_box(src.len()) {
        if let Some(x) = src.get(j) {
            // SAFETY: as this function's.
            unsafe { dst.add(j * stride).write(x.to_n::<N>()) };
        }
    }
}

/// The model's constants in its number type (its own function: built in
/// the caller and copied into the model, the ~90 words were moved one by
/// one, 0.7 KB of init code).
#[inline(never)]
fn consts_of<N: Num, S: Word>(c: &ModelConsts<S>) -> Consts<N> {
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
    Consts {
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
        rc2: f(c.rc2),
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
        t_scale: exact!(1.0 / crate::params::TEMP_TABLE_STEP_K),
        inv_stride: exact!(1.0 / crate::params::COARSE_STRIDE as f64),
        re_q: c.re_q.map(f),
        g_wall: c.g_wall.map(f),
        re_lam: exact!(0.23),
        inv_span: exact!(1.0 / 0.77),
        re3: exact!(3.0),
        inv_span3: exact!(1.0 / 7.0),
        t_min: exact!(crate::params::TEMP_TABLE_MIN_C),
        tab_last: exact!((N_TABLE - 2) as f64),
        ga: c.ga.map(f),
        gb: c.gb.map(f),
        gr: c.gr.map(f),
        h: exact!(S_PER_STEP),
        inv_h: exact!(1.0 / S_PER_STEP),
        half: exact!(0.5),
        per_rad_t: exact!(1.0 / RAD_T_K),
        rad_offset: exact!(273.15 / RAD_T_K),
        one: exact!(1.0),
    }}
