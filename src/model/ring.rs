//! The oil ring's quasi-steady links: the pump's inlet and outlet port passages and
//! the ball/needle-valve passage, solved in flow order from the loop node.
//!
//! Each link `i` with inflow capacity rate `m_in` at `T_up`, film conductance `g`
//! to its metal at `T_m`, heat input `P` and capacity `C` moving at the ring's rate
//! `r` satisfies `C r = m_in (T_up - T_i) + g (T_m - T_i) + P`, so
//! `T_i = (m_in T_up + g T_m + P - C r) / (m_in + g)` (mass-consistent: what flows
//! in flows out). With the flow stopped (`m = 0`) a link relaxes onto its metal.
//!
//! Forward flow (pump delivering into port A): loop → (exchanger) → inlet → outlet
//! → {ball-valve passage (throttled flow), actuator chambers (piston flow)} → loop.
//! Reverse: loop → (exchanger) → {ball-valve passage, direct} → outlet → inlet → loop.
//! The leakage `m_l` leaves the ring at the high-pressure port for the case.

use crate::num::Num;

/// Inputs of one solve (model units: degC, kW/K, kW, kJ/K, K/s).
#[derive(Clone, Copy, Debug)]
pub struct RingIn<N> {
    /// Loop node temperature, degC.
    pub t_loop: N,
    /// Pump housing temperature, degC.
    pub t_pump: N,
    /// Ball-valve block temperature, degC.
    pub t_ball_block: N,
    /// Circulating capacity rate through the pump, kW/K.
    pub m_c: N,
    /// Throttled part of it (through the ball-valve passage), kW/K, `<= m_c`.
    pub m_thr: N,
    /// Leakage capacity rate (high-pressure port → case → loop), kW/K.
    pub m_l: N,
    /// One port passage ↔ pump housing conductance, kW/K (> 0).
    pub g_port: N,
    /// Ball-valve passage ↔ its block, kW/K (> 0).
    pub g_ball: N,
    /// Heat the exchanger removes from the loop outflow now, kW.
    pub q_lng: N,
    /// The same as it has reached the high-pressure port (transport delay), kW.
    pub q_lng_port: N,
    /// Mechanical-loss share heating the high-pressure port oil, kW.
    pub p_hp: N,
    /// Needle-valve throttling heat in the ball-valve passage, kW.
    pub p_needle: N,
    /// Capacity of one port passage, kJ/K.
    pub c_port: N,
    /// Capacity of the ball-valve passage, kJ/K.
    pub c_ball: N,
    /// Ring rate of the last step, K/s.
    pub rate: N,
    /// The pump delivers into port A (forward ring order).
    pub forward: bool,
    /// Port A is the high-pressure port.
    pub hp_is_a: bool,
    /// 1 in the number type.
    pub one: N,
}

/// Result of one solve.
#[derive(Clone, Copy, Debug)]
pub struct Ring<N> {
    /// Inlet (port B side in forward flow) passage, degC.
    pub t_in: N,
    /// Outlet (port A) passage, degC.
    pub t_out: N,
    /// Ball-valve passage, degC.
    pub t_ball: N,
    /// Temperature of the leakage entering the case (high-pressure port, with the
    /// exchanger's cooling as far as it has arrived there), degC.
    pub t_feed: N,
    /// Heat removed by the exchanger, kW.
    pub q_lng: N,
}

impl<N: Num> Ring<N> {
    /// Solves the links in flow order (three divisions).
    #[inline(always)]
    pub fn solve(x: &RingIn<N>) -> Self {
        let m0 = x.m_c.add(x.m_l);
        let one_pump = x.g_port.mul(x.t_pump);
        let cr_port = x.c_port.mul(x.rate);
        let cr_ball = x.c_ball.mul(x.rate);
        // Heat input of a port passage: the mechanical share at the high-pressure one.
        let (p_a, p_b) = if x.hp_is_a { (x.p_hp, N::ZERO) } else { (N::ZERO, x.p_hp) };
        let lead = |m: N| x.one.div_pos(m.add(x.g_port));
        if x.forward {
            // loop → inlet (B side): carries m_c + m_l (the leak leaves at A or B)
            let d_in = lead(m0);
            let t_in = m0.mul(x.t_loop).sub(x.q_lng).add(one_pump).add(p_b).sub(cr_port).mul(d_in);
            let m1 = if x.hp_is_a { m0 } else { x.m_c };
            let d_out = lead(m1);
            let t_out = m1.mul(t_in).add(one_pump).add(p_a).sub(cr_port).mul(d_out);
            let t_ball = x
                .m_thr
                .mul(t_out)
                .add(x.g_ball.mul(x.t_ball_block))
                .add(x.p_needle)
                .sub(cr_ball)
                .div_pos(x.m_thr.add(x.g_ball));
            // d T_hp / d q_lng = -d_in (inlet), -d_in m1 d_out (outlet)
            let lag = x.q_lng.sub(x.q_lng_port);
            let t_feed = if x.hp_is_a {
                t_out.add(lag.mul(d_in).mul(m1).mul(d_out))
            } else {
                t_in.add(lag.mul(d_in))
            };
            Ring { t_in, t_out, t_ball, t_feed, q_lng: x.q_lng }
        } else {
            // loop → {ball passage (m_thr), direct (m_act + m_l)} → outlet (A) → inlet (B) → loop;
            // the exchanger's cooling is taken by the larger of the two branches.
            let m_direct = x.m_c.sub(x.m_thr).add(x.m_l);
            let on_direct = m_direct >= x.m_thr;
            let (q_d, q_b) = if on_direct { (x.q_lng, N::ZERO) } else { (N::ZERO, x.q_lng) };
            let t_ball = x
                .m_thr
                .mul(x.t_loop)
                .sub(q_b)
                .add(x.g_ball.mul(x.t_ball_block))
                .add(x.p_needle)
                .sub(cr_ball)
                .div_pos(x.m_thr.add(x.g_ball));
            let d_out = lead(m0);
            let t_out = x
                .m_thr
                .mul(t_ball)
                .add(m_direct.mul(x.t_loop))
                .sub(q_d)
                .add(one_pump)
                .add(p_a)
                .sub(cr_port)
                .mul(d_out);
            let m2 = if x.hp_is_a { x.m_c } else { m0 };
            let d_in = lead(m2);
            let t_in = m2.mul(t_out).add(one_pump).add(p_b).sub(cr_port).mul(d_in);
            // delayed cooling at the port, through the direct branch
            let lag = if on_direct { x.q_lng.sub(x.q_lng_port) } else { N::ZERO };
            let t_feed = if x.hp_is_a {
                t_out.add(lag.mul(d_out))
            } else {
                t_in.add(lag.mul(d_out).mul(m2).mul(d_in))
            };
            Ring { t_in, t_out, t_ball, t_feed, q_lng: x.q_lng }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn base(forward: bool, hp_is_a: bool) -> RingIn<f64> {
        RingIn {
            t_loop: 40.0,
            t_pump: 40.0,
            t_ball_block: 40.0,
            m_c: 0.26,
            m_thr: 0.26,
            m_l: 0.003,
            g_port: 0.002,
            g_ball: 0.002,
            q_lng: 0.0,
            q_lng_port: 0.0,
            p_hp: 0.0,
            p_needle: 0.0,
            c_port: 0.085,
            c_ball: 0.085,
            rate: 0.0,
            forward,
            hp_is_a,
            one: 1.0,
        }
    }

    /// Everything at one temperature, no heat: every link at that temperature, in
    /// both flow directions and with either port at high pressure.
    #[test]
    fn isothermal_ring_stays_isothermal() {
        for (f, h) in [(true, true), (true, false), (false, true), (false, false)] {
            let r = Ring::solve(&base(f, h));
            for t in [r.t_in, r.t_out, r.t_ball, r.t_feed] {
                assert!((t - 40.0).abs() < 1e-12, "forward {f} hp A {h}: {t}");
            }
        }
    }

    /// A heat input P on the high-pressure port raises the outlet by P / (m + g)
    /// (m = the capacity rate through it), and the ball passage downstream by the
    /// same advected amount less what its film passes to the block.
    #[test]
    fn heat_input_raises_the_stream_downstream() {
        let mut x = base(true, true);
        x.p_hp = 0.3; // kW
        let r = Ring::solve(&x);
        let m1 = x.m_c + x.m_l;
        assert!((r.t_in - 40.0).abs() < 1e-12);
        assert!((r.t_out - (40.0 + 0.3 / (m1 + x.g_port))).abs() < 1e-12);
        let expect_ball = (x.m_thr * r.t_out + x.g_ball * 40.0) / (x.m_thr + x.g_ball);
        assert!((r.t_ball - expect_ball).abs() < 1e-12);
        assert!((r.t_feed - r.t_out).abs() < 1e-12, "the leakage leaves at the high-pressure (outlet) port");
    }

    /// The exchanger's heat leaves the loop outflow: the inlet drops by q / (m0 + g);
    /// while it has not reached the port (`q_lng_port = 0`) the drain feed is the
    /// outlet as if the exchanger were off.
    #[test]
    fn exchanger_cools_the_inlet_and_reaches_the_feed_late() {
        let mut x = base(true, true);
        x.q_lng = 3.0;
        x.q_lng_port = 0.0;
        let r = Ring::solve(&x);
        let m0 = x.m_c + x.m_l;
        assert!((r.t_in - (40.0 - 3.0 / (m0 + x.g_port))).abs() < 1e-12);
        assert!(r.t_out < 40.0 - 10.0, "outlet {}", r.t_out);
        assert!((r.t_feed - 40.0).abs() < 1e-9, "feed {}", r.t_feed);
        x.q_lng_port = 3.0;
        let r2 = Ring::solve(&x);
        assert!((r2.t_feed - r2.t_out).abs() < 1e-12);
    }

    /// With the flow stopped each link relaxes onto its metal plus its heat over the film.
    #[test]
    fn stopped_flow_links_sit_on_their_metal() {
        let mut x = base(true, true);
        x.m_c = 0.0;
        x.m_thr = 0.0;
        x.m_l = 0.0;
        x.t_pump = 30.0;
        x.t_ball_block = 25.0;
        x.p_needle = 0.001;
        let r = Ring::solve(&x);
        assert!((r.t_in - 30.0).abs() < 1e-12 && (r.t_out - 30.0).abs() < 1e-12);
        assert!((r.t_ball - (25.0 + 0.001 / x.g_ball)).abs() < 1e-12);
    }
}
