//! The model's constants in model units (kW, L/s, hbar, hrad/s, degC): what the
//! firmware needs to run the reduced model, derived once from the SI
//! [`crate::params::ReducedParams`] on the host ([`derive()`], `f64`) and carried to the target as
//! `f32` (the compiled-in [`crate::model::DEFAULT_CONSTS`] or a parameter block
//! in flash, [`crate::params_block`]). The target does no `f64` arithmetic and no
//! matrix exponential: it converts these values into its number type and checks them.

use super::ConfigError;
use crate::num::Num;
use crate::params::{
    FILM_PROPERTY_C, N_COARSE, N_DUCTS, N_RE, NODE_ACTUATOR, NODE_BALL_BLOCK, NODE_MAIN_BLOCK, N_NODES, N_OUTER, N_PHI, N_STATES,
    N_TABLE, N_TEMP, S_PER_STEP, TEMP_TABLE_MIN_C, TEMP_TABLE_STEP_K,
};

mod derive;
pub use derive::derive;

/// Defines [`ModelConsts`] from one list of its fields (in word order, the
/// only listing of them) with the walks over every field: [`ModelConsts::map`]
/// and the field skeleton (`ModelConsts::<()>::UNIT`). A field's type is `S`,
/// `[S; n]` or `[[S; n]; m]`.
macro_rules! model_consts {
    ($(#[$sm:meta])* pub struct ModelConsts<S> { $( $(#[$fm:meta])* $name:ident : $ty:tt, )* }) => {
        $(#[$sm])*
        pub struct ModelConsts<S> {
            $( $(#[$fm])* pub $name: $ty, )*
        }

        impl<S: Copy> ModelConsts<S> {
            /// Applies `f` to every word, in word order.
            pub fn map<T: Copy>(&self, mut f: impl FnMut(S) -> T) -> ModelConsts<T> {
                let c = self;
                ModelConsts { $( $name: map_field!(f, c.$name, $ty), )* }
            }
        }

        impl ModelConsts<()> {
            /// The field skeleton (for [`ModelConsts::from_words`]).
            const UNIT: Self = ModelConsts { $( $name: unit_field!($ty), )* };
        }
    };
}

/// One field of [`ModelConsts::map`]: `f` applied to each of its words.
macro_rules! map_field {
    ($f:ident, $x:expr, [[S; $n:expr]; $m:expr]) => {
        $x.map(|r| r.map(&mut $f))
    };
    ($f:ident, $x:expr, [S; $n:expr]) => {
        $x.map(&mut $f)
    };
    ($f:ident, $x:expr, S) => {
        $f($x)
    };
}

/// One field of the skeleton `ModelConsts::<()>::UNIT`.
macro_rules! unit_field {
    ([[S; $n:expr]; $m:expr]) => {
        [[(); $n]; $m]
    };
    ([S; $n:expr]) => {
        [(); $n]
    };
    (S) => {
        ()
    };
}

model_consts! {
    /// Constants of the reduced model in model units, scalar type `S` (`f64` on the
    /// host, `f32` in a parameter block). Field order is the block's word order.
    #[derive(Clone, Copy, Debug, PartialEq)]
    #[repr(C)]
    pub struct ModelConsts<S> {
        /// Case pressure, hbar.
        p_case: S,
        /// Pump leakage flow per port, L/s per hbar (eqs. 5-7).
        k_lf: S,
        /// Half of [`Self::k_lf`] (the case receives the mean of both ports' leakage).
        k_lf_half: S,
        /// Pump leakage heat, kW per hbar^2 (eqs. 5-7).
        k_lp: S,
        /// Pump mechanical loss, kW per (hbar hrad/s) (eq. 8).
        k_mech: S,
        /// Pump flow, L/s per hrad/s.
        k_q: S,
        /// Piston flow, L/s per (mm per tick).
        k_a: S,
        /// Throttling power, kW per (hbar L/s).
        k_dpq: S,
        /// Line loss, kW per (L/s)^2 (eq. 10, laminar part).
        r1: S,
        /// Line loss, kW per (L/s)^3 (eq. 10, local losses).
        r2: S,
        /// Actuator heat weight of `dp^2` (eq. 11), of [`Self::k_act`] (≤ 1).
        w_dp: S,
        /// Actuator heat weight of `dx^2` (seal friction), of [`Self::k_act`] (≤ 1).
        w_dx: S,
        /// Actuator heat scale, kW: `k_act (w_dp dp^2 + w_dx dx^2)` per tick.
        k_act: S,
        /// Copper loss, kW per hA^2 (eq. 1).
        k_cu: S,
        /// Shaft power from the current, kW per (hA hrad/s) (cross-check); 0 disables it.
        k_sh: S,
        /// Hydraulic power of the displacement, kW per (hbar hrad/s) (cross-check).
        k_hyd: S,
        /// Iron loss, hysteresis, kW per hrad/s (eq. 2).
        fe1: S,
        /// Iron loss, eddy, kW per (hrad/s)^2 (eq. 2).
        fe2: S,
        /// Iron loss, excess, kW per (hrad/s)^1.5 (eq. 2).
        fe15: S,
        /// Flow-table index scale `(N_TABLE - 1) / sqrt(q_max)`, per sqrt(L/s).
        q_scale: S,
        /// Speed-table index scale `(N_TABLE - 1) / sqrt(w_max)`, per sqrt(hrad/s).
        w_scale: S,
        /// Oil `rho c_p` at 0 degC, kJ/(L K).
        rc0: S,
        /// Slope of `rho c_p`, kJ/(L K^2).
        rc1: S,
        /// Curvature of `rho c_p`, kJ/(L K^3) (density and specific heat both linear).
        rc2: S,
        /// 1 / case oil volume, 1/L.
        inv_v_case: S,
        /// 1 / loop oil volume, 1/L.
        inv_v_loop: S,
        /// One port passage's oil volume, L.
        v_port: S,
        /// Ball-valve passage oil volume, L.
        v_ball: S,
        /// 1 / ring oil volume, 1/L.
        inv_v_ring: S,
        /// Share of the pump's viscous and pressure friction into the delivered oil.
        f_out: S,
        /// Share of the pump's viscous and pressure friction into the case oil;
        /// `1 - f_out - f_case` heats the pump housing (with the no-load friction).
        f_case: S,
        /// Pump no-load friction, kW per hrad/s (extended eq. 8).
        k_m0: S,
        /// Pump viscous friction at 40 degC, kW per (hrad/s)^2 (extended eq. 8).
        k_mv: S,
        /// Oil expansion coefficient alpha, 1/K (compression and throttling, h(T, p)).
        alpha: S,
        /// Relative slope of the case film conductance with the case-oil temperature,
        /// 1/K, about `FILM_PROPERTY_C` (may be negative).
        g_case_slope: S,
        /// `alpha * 273.15`: `alpha T` with T in kelvin is `alpha_t0 + alpha t_degC`.
        alpha_t0: S,
        /// LNG inlet temperature, degC (eqs. 20-22).
        lng_in: S,
        /// Motor pole pairs (the speed check's electrical frequency, `crate::speedcheck`).
        pole_pairs: S,
        /// Commissioning safety margin on the drain-oil estimate, K: added by the
        /// guard to the model's case oil for every decision and report, never fed
        /// back into the model ([`ReducedParams::drain_margin_k`](crate::params::ReducedParams::drain_margin_k)).
        drain_margin_k: S,
        /// 1 / capacity of the metal states, K/kJ (oil nodes 0).
        inv_c: [S; N_STATES],
        /// Outer surfaces, constant conductance, kW/K (eqs. 15-16).
        ga: [S; N_OUTER],
        /// Outer surfaces, `|dT|^(1/4)` conductance, kW/K^1.25.
        gb: [S; N_OUTER],
        /// Outer surfaces, radiation `4 eps sigma A (300 K)^3`, kW/K (eq. 19).
        gr: [S; N_OUTER],
        /// Case oil <-> pump housing over `sqrt` speed grid, kW/K.
        g_case: [S; N_TABLE],
        /// Port passage <-> pump housing over flow, kW/K.
        g_port: [S; N_TABLE],
        /// Loop oil <-> main block over flow, kW/K.
        g_loop: [S; N_TABLE],
        /// Ball-valve oil <-> its block over flow, kW/K.
        g_ball: [S; N_TABLE],
        /// LNG exchanger `eps C_min` over flow, kW/K (eqs. 20-22).
        g_lng: [S; N_TABLE],
        /// Leakage ratio `mu(40) / mu(T)` over the temperature grid (1 at 40 degC,
        /// non-decreasing).
        leak_ratio: [S; N_TEMP],
        /// Viscous friction ratio `mu(T) / mu(40)` over the temperature grid (1 at
        /// 40 degC, non-increasing).
        visc_ratio: [S; N_TEMP],
        /// Case-gap speed factor `nu(40) / nu(T)` over the temperature grid (1 at
        /// 40 degC, non-decreasing).
        tc_speed: [S; N_TEMP],
        /// Reynolds number of each duct (port, loop, ball) over 1e4 per L/s of flow at
        /// the 40 degC viscosity.
        re_q: [S; N_DUCTS],
        /// Block walls behind the loop's and the ball-valve passage's films, kW/K.
        g_wall: [S; 2],
        /// The ducts' films at the Reynolds numbers of `params::DUCT_RE` (2300, 1e4,
        /// 3e4, 1e5) on the coarse temperature grid, kW/K: per point `[port 2300, port
        /// 1e4, port 3e4, port 1e5, loop ..., ball ...]`.
        g_trans: [[S; N_RE * N_DUCTS]; N_COARSE],
        /// Cooling at rest: decay rate of each node's bound on its excess over
        /// the air, 1/s (all 0: no bound; [`ReducedParams::rest_rate_per_s`](crate::params::ReducedParams::rest_rate_per_s)).
        rest_rate: [S; N_NODES],
        /// Cooling at rest: the bound's mode shape, node order, in (0, 1]
        /// ([`ReducedParams::rest_mode`](crate::params::ReducedParams::rest_mode)).
        rest_mode: [S; N_NODES],
        /// Exact-ZOH matrix `Phi = h phi1(h A)` of the model step over the first
        /// [`N_PHI`] states, s.
        phi: [[S; N_PHI]; N_PHI],
    }
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
}

/// A word of [`ModelConsts`]: `f64` (host design) or `f32` (parameter block).
/// Sealed: [`ModelConsts::as_words`] relies on these two being the only ones.
pub trait Word: Copy + sealed::Sealed {
    /// To the model's number type (saturating for fixed point).
    fn to_n<N: Num>(self) -> N;
    /// To a discretised-matrix coefficient; `None` outside the coefficient range.
    fn to_coef<N: Num>(self) -> Option<N::Coef>;
    /// To `f32` (checks).
    fn to_f32(self) -> f32;
}

impl Word for f32 {
    #[inline(always)]
    fn to_n<N: Num>(self) -> N {
        N::from_f32(self)
    }
    #[inline(always)]
    fn to_coef<N: Num>(self) -> Option<N::Coef> {
        N::coef_from_f32(self)
    }
    #[inline(always)]
    fn to_f32(self) -> f32 {
        self
    }
}

impl Word for f64 {
    fn to_n<N: Num>(self) -> N {
        N::from_f64(self)
    }
    fn to_coef<N: Num>(self) -> Option<N::Coef> {
        N::coef_from_f64(self)
    }
    fn to_f32(self) -> f32 {
        self as f32
    }
}

/// Scalar words at the head of a [`ModelConsts`] (`p_case` .. `drain_margin_k`).
pub const N_SCALARS: usize = 39;
/// Number of words in a [`ModelConsts`].
pub const N_WORDS: usize =
    N_SCALARS + N_STATES + 3 * N_OUTER + 5 * N_TABLE + 3 * N_TEMP + N_DUCTS + 2 + N_RE * N_DUCTS * N_COARSE + 2 * N_NODES + N_PHI * N_PHI;

// Every field is a word: no padding, no other data.
const _: () = assert!(core::mem::size_of::<ModelConsts<f32>>() == 4 * N_WORDS);
const _: () = assert!(core::mem::size_of::<ModelConsts<f64>>() == 8 * N_WORDS);

/// Largest magnitude of any constant (fixed-point value range, with margin).
pub const MAX_ABS: f32 = 250.0;

impl<S: Copy> ModelConsts<S> {
    /// Calls `f` on every word in word order.
    pub fn for_each(&self, f: impl FnMut(S)) {
        let _ = self.map(f);
    }

    /// Builds the constants from words in word order (`next` is called
    /// [`N_WORDS`] times).
    pub fn from_words(mut next: impl FnMut() -> S) -> Self {
        ModelConsts::<()>::UNIT.map(|()| next())
    }
}

impl ModelConsts<f64> {
    /// The `f32` words of a parameter block (round to nearest).
    pub fn to_f32(&self) -> ModelConsts<f32> {
        self.map(|x| x as f32)
    }
}

impl<S: Word> ModelConsts<S> {
    /// The words in field order, in place.
    pub fn as_words(&self) -> &[S; N_WORDS] {
        // SAFETY: `ModelConsts<S>` is `repr(C)` with only `S` fields and arrays
        // of `S` (`S` is `f32` or `f64`, the only `Word`s): no padding, size
        // `N_WORDS` words (asserted above), alignment that of `S`.
        unsafe { &*(self as *const Self).cast::<[S; N_WORDS]>() }
    }

    /// Value checks that need no model: every word finite and below
    /// [`MAX_ABS`]; capacities, volumes, conductances, tables, loss coefficients
    /// and shares non-negative; shares and the rest mode ≤ 1; the links' zero-flow conductances and
    /// the table scales positive. The stability of the discretisation is checked
    /// by [`crate::model::Model::check_stability`].
    pub fn check_values(&self) -> Result<(), ConfigError> {
        let finite = self.as_words().iter().all(|x| {
            let x = x.to_f32();
            x.is_finite() && x.abs() < MAX_ABS
        });
        if !finite {
            return Err(ConfigError::ConstantRange);
        }
        let c = self;
        let w = |x: S| x.to_f32();
        let scalars_non_neg = [
            c.k_lf, c.k_lf_half, c.k_lp, c.k_mech, c.k_q, c.k_a, c.k_dpq, c.r1, c.r2, c.w_dp, c.w_dx, c.k_act, c.k_cu, c.k_sh, c.k_hyd,
            c.fe1, c.fe2, c.fe15, c.inv_v_case, c.inv_v_loop, c.v_port, c.v_ball, c.inv_v_ring, c.f_out,
            c.f_case, c.k_m0, c.k_mv, c.alpha, c.alpha_t0,
        ];
        // inv_c, outer conductances and the tables: every word between the
        // scalars and Phi (a rolled loop: init code, flash)
        let arrays = self.as_words().get(core::hint::black_box(N_SCALARS)..N_WORDS - N_PHI * N_PHI).unwrap_or(&[]);
        let non_neg = scalars_non_neg.iter().all(|x| w(*x) >= 0.0) && arrays.iter().all(|x| w(*x) >= 0.0);
        let pos = [c.q_scale, c.w_scale, c.inv_v_case, c.inv_v_loop, c.v_port, c.v_ball, c.inv_v_ring, c.g_port[0], c.g_ball[0]]
            .iter()
            .all(|x| w(*x) > 0.0);
        let shares = w(c.w_dp) <= 1.0 && w(c.w_dx) <= 1.0 && w(c.f_out) + w(c.f_case) <= 1.0;
        let mode = c.rest_mode.iter().all(|v| w(*v) <= 1.0);
        // rho c_p stays positive over the oil's range (-60..150 degC)
        let rc = |t: f32| w(c.rc0) + w(c.rc1) * t + w(c.rc2) * t * t;
        let rc = rc(-60.0) > 0.0 && rc(40.0) > 0.0 && rc(150.0) > 0.0;
        // the temperature tables: 1 at 40 degC (where the other words are
        // referred; 1e-3 covers f32 rounding), monotonic as the viscosity
        // falls with temperature (the leakage and the gap's Taylor number rise,
        // the viscous friction falls), positive (every word >= 0 is checked above)
        let at40 = ((FILM_PROPERTY_C - TEMP_TABLE_MIN_C) / TEMP_TABLE_STEP_K) as usize;
        // (slices of a black-boxed length: rolled loops, init code, flash)
        fn sl<S>(t: &[S; N_TEMP]) -> &[S] {
            t.get(..core::hint::black_box(N_TEMP)).unwrap_or(&[])
        }
        let unit = |t: &[S; N_TEMP]| t.get(at40).is_some_and(|x| (w(*x) - 1.0).abs() <= 1e-3) && sl(t).iter().all(|x| w(*x) > 0.0);
        let rising = |t: &[S; N_TEMP]| sl(t).windows(2).all(|p| p.first().zip(p.get(1)).is_some_and(|(a, b)| w(*b) >= w(*a)));
        let falling = |t: &[S; N_TEMP]| sl(t).windows(2).all(|p| p.first().zip(p.get(1)).is_some_and(|(a, b)| w(*b) <= w(*a)));
        let temp = unit(&c.leak_ratio)
            && unit(&c.visc_ratio)
            && unit(&c.tc_speed)
            && rising(&c.leak_ratio)
            && rising(&c.tc_speed)
            && falling(&c.visc_ratio);
        let euler = self.euler_steps_are_small();
        if non_neg && pos && shares && mode && rc && temp && euler {
            Ok(())
        } else {
            Err(ConfigError::Implausible)
        }
    }
}

/// Largest piston travel per tick the Euler check allows for, mm (1 m/s: beyond any
/// EHA's rate; the tidal exchange with the loop oil grows with it).
const MAX_DPOS_MM_PER_TICK: f32 = 10.0;

impl<S: Word> ModelConsts<S> {
    /// The states advanced by explicit Euler (`params::EULER_STATES`) take steps
    /// small against their time constants: the model step times the largest sum of
    /// each one's conductances over its capacity is at most 0.5 (Euler is stable up
    /// to 2; the paper rig's are below 2e-3). The bound takes every table at its
    /// maximum, the outer surfaces at 200 K above the air and the tidal exchange at
    /// [`MAX_DPOS_MM_PER_TICK`].
    fn euler_steps_are_small(&self) -> bool {
        let c = self;
        let w = |x: S| x.to_f32();
        let max = |t: &[S; N_TABLE]| t.get(..core::hint::black_box(N_TABLE)).unwrap_or(&[]).iter().fold(0.0f32, |m, x| m.max(w(*x)));
        // (200 K)^(1/4) = 3.76; T_m (T_m^2 + d^2) at T_m = 1.6 (480 K), d = 0.33 in units of 300 K: 4.3
        let outer = |i: usize| match (c.ga.get(i), c.gb.get(i), c.gr.get(i)) {
            (Some(a), Some(b), Some(r)) => w(*a) + 3.8 * w(*b) + 4.3 * w(*r),
            _ => f32::INFINITY,
        };
        let rc_max = w(c.rc0).abs() + 150.0 * w(c.rc1).abs() + 22_500.0 * w(c.rc2).abs();
        let tidal = rc_max * w(c.k_a) * MAX_DPOS_MM_PER_TICK;
        let sums = [
            (NODE_MAIN_BLOCK, max(&c.g_loop) + outer(1)),
            (NODE_BALL_BLOCK, max(&c.g_ball) + outer(2)),
            (NODE_ACTUATOR, tidal + outer(3)),
        ];
        sums.iter().all(|(i, g)| c.inv_c.get(*i).is_some_and(|ic| S_PER_STEP as f32 * g * w(*ic) <= 0.5))
    }
}
