//! The linear part of the thermal steps: A, the Jacobian of the heat
//! balances by forward differences ([`Thermal::jacobian`]), the drift of
//! some of its columns kept beside it ([`Thermal::drift`]), and f anew
//! where the forcing changed ([`Thermal::fresh`]).

use super::{Rates, Thermal, NE, NT};
use crate::fast::dense::transpose;

impl Thermal {
    /// f anew at z, and A by forward differences (N_NODES more
    /// evaluations). With `keep_history` the stored g are rewritten for the
    /// new A (g = f − A·z changes by (A_old − A_new)·z).
    pub fn jacobian(&mut self, rates: &mut impl Rates, keep_history: bool) {
        let a_old = self.a;
        let (mut fz, mut q) = ([0.0; NT], [0.0; NE]);
        rates(&self.z, &mut fz, &mut q);
        for j in 0..NT {
            let col = self.column(rates, j, &fz, &q);
            for (i, x) in col.iter().enumerate() {
                self.a[i][j] = *x;
            }
        }
        self.a_cols = transpose(&self.a);
        self.da_cols = None;
        self.da_n = 0;
        self.a_zero = self.a.iter().all(|r| r.iter().all(|&x| x == 0.0));
        if keep_history {
            for (_, g, z) in self.hist.iter_mut() {
                for (i, gi) in g.iter_mut().enumerate() {
                    *gi += (0..NT).map(|j| (a_old[i][j] - self.a[i][j]) * z[j]).sum::<f64>();
                }
            }
        } else {
            self.hist.clear();
        }
        (self.fz, self.q) = (fz, q);
    }

    /// Column `j` of the temperatures' Jacobian by a forward difference from
    /// `fz`, `q` (the rates at z): returned; the energies' column is written
    /// into `a_e` (one evaluation).
    fn column(&mut self, rates: &mut impl Rates, j: usize, fz: &[f64; NT], q: &[f64; NE]) -> [f64; NT] {
        let (mut fp, mut qp) = ([0.0; NT], [0.0; NE]);
        let mut zp = self.z;
        let d = 1e-5 * (1.0 + self.z[j].abs());
        zp[j] += d;
        rates(&zp, &mut fp, &mut qp);
        for i in 0..NE {
            self.a_e[i][j] = (qp[i] - q[i]) / d;
        }
        std::array::from_fn(|i| (fp[i] - fz[i]) / d)
    }

    /// The columns `cols` of the Jacobian anew by forward differences
    /// (1 + cols.len() evaluations), kept as Â − A beside A: the φ-functions
    /// stay those of A, the corrector treats the difference implicitly.
    pub fn drift(&mut self, rates: &mut impl Rates, cols: &[usize]) {
        let (mut fz, mut q) = ([0.0; NT], [0.0; NE]);
        rates(&self.z, &mut fz, &mut q);
        let mut da = self.da_cols.unwrap_or([[0.0; NT]; NT]);
        for &j in cols {
            let col = self.column(rates, j, &fz, &q);
            for (i, x) in col.iter().enumerate() {
                da[j][i] = x - self.a[i][j];
            }
            if !self.da_idx[..self.da_n].contains(&j) {
                self.da_idx[self.da_n] = j;
                self.da_n += 1;
            }
        }
        self.da_norm = da.iter().map(|c| c.iter().map(|x| x.abs()).sum::<f64>()).fold(0.0, f64::max);
        self.da_cols = Some(da);
    }

    /// f anew at z (the forcing changed: a breakpoint, the far side of a
    /// branch switch, a valve). With `keep_history` the stored g are
    /// shifted by the jump of g here (a step in the forcing, its
    /// derivatives unchanged); without, they are forgotten.
    pub fn fresh(&mut self, rates: &mut impl Rates, keep_history: bool) {
        let old = self.fz;
        rates(&self.z, &mut self.fz, &mut self.q);
        if keep_history {
            for (_, g, _) in self.hist.iter_mut() {
                for i in 0..NT {
                    g[i] += self.fz[i] - old[i];
                }
            }
        } else {
            self.hist.clear();
        }
    }
}
