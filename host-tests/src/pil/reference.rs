//! The reference plant (`eha_sim::plant::Plant`) as a [`PlantModel`].

use std::f64::consts::PI;

use anyhow::anyhow;

use crate::network::Node;
use crate::plant::{Control, Plant, Snapshot};

use super::{PlantModel, PlantSensors, StepControl};

/// Sensor values in wire units from a plant snapshot.
pub fn sensors(snap: &Snapshot) -> PlantSensors {
    let op = &snap.op;
    PlantSensors {
        current_a: op.current_a,
        p_a_bar: op.p_a / 1e5,
        p_b_bar: op.p_b / 1e5,
        speed_rpm: op.omega * 60.0 / (2.0 * PI),
        position_mm: op.x * 1e3,
        ambient_c: op.ambient_c,
        t_drain_c: snap.temp(Node::Case),
        t_oil_c: Some(snap.temp(Node::Sensor)),
        valve_fb: Some(snap.lng_open),
        elec_hz: None,
        lng_supply_bar: None,
    }
}

impl PlantModel for Plant {
    fn run(
        &mut self,
        dt_s: f64,
        t_end_s: f64,
        on_step: &mut dyn FnMut(f64, &PlantSensors) -> StepControl,
    ) -> anyhow::Result<()> {
        Plant::run(self, dt_s, t_end_s, |snap| {
            Ok(match on_step(snap.t, &sensors(snap)) {
                StepControl::Valve(v) => Control { lng_valve: Some(v), stop: false },
                StepControl::Stop => Control { lng_valve: None, stop: true },
            })
        })
        .map_err(|e| anyhow!("reference plant: {e}"))
    }
}
