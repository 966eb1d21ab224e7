//! The pump's loss coefficient `eta_m` (eq. 8) from the logs' electrical
//! balance: the commissioning holds it there and the diagnosis's structure
//! takes it from here ([`eta_m_balance`], [`eta_m_from_current`]).

use super::log::CalLog;
use crate::rig::Rig;

/// The pump's loss coefficient `eta_m` of eq. (8) from the logs' electrical
/// balance, as the firmware's sensor cross-check sees it: the shaft power
/// from the current `Kt |I| |w|` (signed like the shaft torque) minus the
/// displacement's hydraulic power `D dp w` is the friction `T0 |w| + C_v mu D
/// w^2 + eta_m D |dp| |w|` (extended eq. 8). With `T0` and `C_v` held at the
/// rig file, `eta_m` by least squares over the rows whose `D |dp| |w|` is at
/// least 20 % of the logs' largest (light load says little), with `Kt` and `D`
/// from the rig file. The viscous term at the oil's viscosity where the log
/// reads it: its drain thermocouple, else its manifold oil sensor (a few kelvin
/// colder than the case oil), else 40 °C. (At 40 °C throughout, the viscous
/// friction of oil at 20 °C, 2.2 times its 40 °C value, went into `eta_m`, and the
/// firmware, whose friction follows the oil, saw its own
/// cross-check disagree within a second.)
/// [`EtaMBalance::NoLoadedRows`] without current or load.
pub fn eta_m_balance(rig: &Rig, logs: &[CalLog]) -> EtaMBalance {
    use crate::measured::Channel;
    let kt = rig.motor.torque_constant_nm_per_a;
    let d = rig.displacement_m3_per_rad();
    let p = &rig.pump;
    let mut rows = Vec::new();
    for l in logs {
        let r = &l.run;
        let (Some(i), Some(w), Some(pa), Some(pb)) = (r.get(Channel::CurrentA), r.get(Channel::SpeedRpm), r.get(Channel::PABar), r.get(Channel::PBBar)) else {
            continue;
        };
        let (drain, oil) = (r.get(Channel::TDrainC), r.get(Channel::TOilC));
        for k in 0..r.len() {
            let (Some(i), Some(w), Some(pa), Some(pb)) = (i[k], w[k], pa[k], pb[k]) else { continue };
            let at = |c: Option<&[Option<f64>]>| c.and_then(|v| v.get(k).copied().flatten());
            let mu = rig.oil.mu_pa_s(at(drain).or(at(oil)).unwrap_or(40.0));
            let w = w * std::f64::consts::PI / 30.0;
            let dp = (pa - pb) * 1e5;
            let hyd = d * dp * w;
            let speed_w = p.no_load_torque_nm * w.abs() + p.viscous_torque_coeff * mu * d * w * w;
            let pressure_w = d * dp.abs() * w.abs();
            // torque sign: D dp + sign(w) T_f with the rig file's friction
            let sign = (hyd + speed_w + p.eta_m * pressure_w).signum();
            let shaft = kt * i.abs() * w.abs() * sign;
            rows.push((shaft - hyd - speed_w, pressure_w));
        }
    }
    let top = rows.iter().map(|r| r.1).fold(0.0, f64::max);
    let used: Vec<_> = rows.into_iter().filter(|r| top > 0.0 && r.1 >= 0.2 * top).collect();
    let (num, den) = used.iter().fold((0.0, 0.0), |(a, b), (f, m)| (a + f * m, b + m * m));
    if den > 0.0 {
        EtaMBalance::Fitted { eta_m: num / den, rows: used.len() }
    } else {
        EtaMBalance::NoLoadedRows
    }
}

/// The plausible range of `eta_m` from the balance: outside it the rig
/// file's no-load and viscous friction leave the load-proportional share a
/// value no pump has (negative on logs whose load hardly varies).
pub const ETA_M_PLAUSIBLE: std::ops::Range<f64> = 0.01..2.0;

/// The electrical balance's `eta_m` before the plausibility check
/// ([`eta_m_balance`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum EtaMBalance {
    /// No row with current, speed and both port pressures under load.
    NoLoadedRows,
    /// The least-squares `eta_m` (dimensionless, eq. 8) over `rows` loaded rows.
    Fitted {
        /// The fitted coefficient.
        eta_m: f64,
        /// Loaded rows used.
        rows: usize,
    },
}

impl EtaMBalance {
    /// `(eta_m, rows)` when fitted within [`ETA_M_PLAUSIBLE`]; else why it is
    /// not used, in one clause.
    pub fn checked(self) -> Result<(f64, usize), String> {
        match self {
            Self::Fitted { eta_m, rows } if ETA_M_PLAUSIBLE.contains(&eta_m) => Ok((eta_m, rows)),
            Self::Fitted { eta_m, rows } => Err(format!(
                "the electrical balance of {rows} loaded samples gives eta_m = {eta_m:.3}, outside the plausible {}..{} (the logs' load does not separate the pressure-proportional friction from the rig file's no-load and viscous terms)",
                ETA_M_PLAUSIBLE.start, ETA_M_PLAUSIBLE.end
            )),
            Self::NoLoadedRows => Err("no log has motor current under load (current, speed and both port pressures)".into()),
        }
    }

    /// `(eta_m, rows)` when fitted within [`ETA_M_PLAUSIBLE`] ([`Self::checked`]).
    pub fn plausible(self) -> Option<(f64, usize)> {
        self.checked().ok()
    }

    /// Why the balance's `eta_m` is not used ([`Self::checked`]); `None` when it is.
    pub fn refusal(self) -> Option<String> {
        self.checked().err()
    }
}

/// [`eta_m_balance`] within [`ETA_M_PLAUSIBLE`]: `(eta_m, rows)`; `None`
/// without loaded rows or outside the range ([`EtaMBalance::refusal`] says
/// which).
pub fn eta_m_from_current(rig: &Rig, logs: &[CalLog]) -> Option<(f64, usize)> {
    eta_m_balance(rig, logs).plausible()
}
