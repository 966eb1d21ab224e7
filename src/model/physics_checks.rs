//! Checks of a parameter block on its own model, at init (after the bounds
//! and the stability of the discretisation): what a per-word range cannot
//! see.
//!
//! * **Minimum heating.** Under the reference load (60 bar across the pump,
//!   500 rpm, every node and the air at 20 °C, valve shut) the model's drain
//!   oil must heat at [`MIN_HEATING_K_PER_S`] or more. The paper rig's heats at
//!   0.232 K/s there (13.9 K/min); the floor is 23 times lower, so an EHA
//!   with far smaller losses against its oil passes, and a block whose loss
//!   coefficients were left at zero (the estimate would sit at ambient and
//!   the valve never open) does not.
//! * **The cooling bound at rest.** The block's `rest_rate` and `rest_mode`
//!   promise `T_i - T_air <= c v_i e^(-r_i t)` with the pump stopped
//!   ([`crate::memory::cooling`]); the comparison argument behind it needs
//!   `dT_i/dt <= -r_i (T_i - T_air)` on the ray `T = T_air + c v`. Checked on
//!   the model's own right-hand side at `c` = 20 K and the air at -55, 20
//!   and 70 °C, with 10 % slack for the number type (the paper rig's model
//!   cools 2.2-4.3 times faster than its bound there): a bound that claims
//!   faster cooling than the model is refused, not trusted. Checked in the
//!   floating-point builds (the product images are f32): the fixed-point
//!   right-hand side at zero flow is not precise enough for it (measured on
//!   the paper rig: the loop oil's rate at rest comes out +1.4e-3 K/s at
//!   20 °C air instead of -1.0e-3), so the M3 build takes the bound's words
//!   within their ranges only.

use super::{ConfigError, Model, ModelInputN, HBAR_PER_BAR, HRADS_PER_RPM, NODE_DRAIN, N_NODES};
use crate::num::Num;

/// The least heating rate of the drain oil under the reference load, K/s.
pub const MIN_HEATING_K_PER_S: f32 = 0.01;
/// Reference load: port A 65 bar, port B at 5 bar (60 bar across the pump), 500 rpm.
const REF_P_A_BAR: f64 = 65.0;
const REF_P_B_BAR: f64 = 5.0;
const REF_RPM: f64 = 500.0;
/// Node and air temperature of the heating check, degC.
const REF_C: f32 = 20.0;
/// Excess over the air on the ray of the rest-bound check, K.
const REST_EXCESS_K: f32 = 20.0;
/// Air temperatures of the rest-bound check, degC (the reduction's range).
const REST_AIR_C: [f32; 3] = [-55.0, 20.0, 70.0];
/// Slack of the rest-bound check (a fraction of the claimed rate).
const REST_SLACK: f32 = 0.1;

impl<N: Num> Model<N> {
    /// The minimum-heating check and the check of the cooling bound at rest
    /// (`rate` 1/s, `mode`: the block's words; all-zero rates: no bound, no
    /// check). See the module docs.
    #[inline(never)]
    pub fn check_physics(&self, rate: &[f32; N_NODES], mode: &[f32; N_NODES]) -> Result<(), ConfigError> {
        let u = ModelInputN {
            current_ha: N::ZERO,
            p_a_hbar: N::from_f32((REF_P_A_BAR * HBAR_PER_BAR) as f32),
            p_b_hbar: N::from_f32((REF_P_B_BAR * HBAR_PER_BAR) as f32),
            speed_hrads: N::from_f32((REF_RPM * HRADS_PER_RPM) as f32),
            dpos_mm: N::ZERO,
            ambient_c: N::from_f32(REF_C),
        };
        let d = self.derivative(&[N::from_f32(REF_C); N_NODES], &u, false);
        let heats = d.get(NODE_DRAIN).is_some_and(|r| r.to_f32() >= MIN_HEATING_K_PER_S);
        if !heats {
            return Err(ConfigError::NoHeating);
        }
        if rate.iter().all(|r| *r == 0.0) || !N::FLOAT {
            return Ok(());
        }
        let p_case = self.k.p_case;
        for air in REST_AIR_C {
            let rest = ModelInputN { current_ha: N::ZERO, p_a_hbar: p_case, p_b_hbar: p_case, speed_hrads: N::ZERO, dpos_mm: N::ZERO, ambient_c: N::from_f32(air) };
            let mut t = [N::ZERO; N_NODES];
            for (ti, v) in t.iter_mut().zip(mode.iter()) {
                *ti = N::from_f32(air + REST_EXCESS_K * v);
            }
            let d = self.derivative(&t, &rest, false);
            for ((di, r), v) in d.iter().zip(rate.iter()).zip(mode.iter()) {
                let claimed = -r * REST_EXCESS_K * v * (1.0 - REST_SLACK);
                // (a NaN fails)
                let holds = di.to_f32() <= claimed;
                if !holds {
                    return Err(ConfigError::RestBound);
                }
            }
        }
        Ok(())
    }
}
