//! The pseudo-arclength corrector's maps ([`super::continue_branch`]): the integrators
//! per parameter value, Pⁿ with its monodromy matrix and ∂Pⁿ/∂p (exact or by differences),
//! and the corrector itself (module docs of [`super`]).

use super::*;
use crate::maps::DiscreteMap;

pub(super) struct Solver {
    pub(super) spec: ContinuationSpec,
    /// Propagators of the last few parameter values (p and p ± δ for ∂F/∂p).
    cache: Vec<(f64, Box<dyn Integrator>)>,
    /// Work of the propagators dropped from the cache.
    retired: u64,
}

impl Solver {
    pub(super) fn new(spec: &ContinuationSpec) -> Result<Self, SimError> {
        Ok(Solver {
            spec: spec.clone(),
            cache: Vec::new(),
            retired: 0,
        })
    }

    /// Adaptive steps spent so far ([`Integrator::work`] of every propagator built).
    pub(super) fn work(&self) -> u64 {
        self.retired + self.cache.iter().map(|(_, i)| i.work()).sum::<u64>()
    }

    pub(super) fn at(&mut self, p: f64) -> Result<&mut dyn Integrator, SimError> {
        let i = match self.cache.iter().position(|(v, _)| *v == p) {
            Some(i) => i,
            None => {
                let model = CantileverModel::new(&self.spec.base.with(self.spec.param, p))?;
                if self.cache.len() == 6 {
                    self.retired += self.cache.remove(0).1.work();
                }
                let integ = build(&model, self.spec.integrator.clone(), 0.0, &model.rest())?;
                self.cache.push((p, integ));
                self.cache.len() - 1
            }
        };
        Ok(self.cache[i].1.as_mut())
    }

    /// The branch's map at `p`: the period-n stroboscopic map (n the branch's period) with
    /// ∂Pⁿ/∂p asked for, one iterate of which the corrector evaluates through [`DiscreteMap`].
    fn map_at(&mut self, p: f64) -> Result<StroboscopicMap<'_>, SimError> {
        let (n, param) = (self.spec.period, self.spec.param);
        Ok(StroboscopicMap::new(self.at(p)?, n).with_param_derivative(param))
    }

    /// Pⁿ(z) with its monodromy matrix and, where the integrator provides it, ∂Pⁿ/∂p; the
    /// distance to grazing only when `watched` (else NaN).
    pub(super) fn map(
        &mut self,
        z: &DVector<f64>,
        p: f64,
        watched: bool,
    ) -> Result<FlowMap, SimError> {
        self.map_at(p)?.linearise(z, 1, watched)
    }

    /// The distance to grazing of Pⁿ(z) (as the watched [`Solver::map`] reports it: the same
    /// steps and searches).
    pub(super) fn grazing(&mut self, z: &DVector<f64>, p: f64) -> Result<f64, SimError> {
        DiscreteMap::grazing_distance(&mut self.map_at(p)?, z, 1)
    }

    /// ∂Pⁿ/∂p at (z, p): that of `map` when known, else central differences.
    pub(super) fn dp_of(
        &mut self,
        map: &FlowMap,
        z: &DVector<f64>,
        p: f64,
    ) -> Result<DVector<f64>, SimError> {
        match &map.param_derivative {
            Some(d) => Ok(d.clone()),
            None => self.dp(z, p),
        }
    }

    /// Pⁿ(z) alone, by a flow without the variational equations
    /// ([`DiscreteMap::iterate`]).
    pub(super) fn map_state(&mut self, z: &DVector<f64>, p: f64) -> Result<DVector<f64>, SimError> {
        self.map_at(p)?.iterate(z, 1)
    }

    /// ∂Pⁿ/∂p by central differences of flows without the variational equations (two flows
    /// whose steps are chosen alike, each a seventh of a variational flow at N = 3 for the
    /// adaptive integrator); one-sided (first order) at the edge of the parameter's valid
    /// range, so that a branch continued up to a limit (Ω = 1e5, say) never evaluates the
    /// model at a value the user did not give and the validation refuses.
    pub(super) fn dp(&mut self, z: &DVector<f64>, p: f64) -> Result<DVector<f64>, SimError> {
        let d = 1e-6 * p.abs().max(1.0);
        let valid = |q: f64| self.spec.base.with(self.spec.param, q).validate().is_ok();
        match (valid(p + d), valid(p - d)) {
            (false, true) => {
                let here = self.map_state(z, p)?;
                let minus = self.map_state(z, p - d)?;
                Ok((here - minus) / d)
            }
            (true, false) => {
                let plus = self.map_state(z, p + d)?;
                let here = self.map_state(z, p)?;
                Ok((plus - here) / d)
            }
            _ => {
                let plus = self.map_state(z, p + d)?;
                let minus = self.map_state(z, p - d)?;
                Ok((plus - minus) / (2.0 * d))
            }
        }
    }

    /// Bordered Jacobian [[M − I, F_p], [tᵀ]].
    pub(super) fn bordered(m: &DMatrix<f64>, fp: &DVector<f64>, t: &DVector<f64>) -> DMatrix<f64> {
        let dim = m.nrows();
        let mut j = DMatrix::zeros(dim + 1, dim + 1);
        j.view_mut((0, 0), (dim, dim))
            .copy_from(&(m - DMatrix::identity(dim, dim)));
        j.view_mut((0, dim), (dim, 1)).copy_from(fp);
        j.view_mut((dim, 0), (1, dim + 1)).copy_from(&t.transpose());
        j
    }

    /// Unit tangent of the branch from the bordered system with ∂F/∂p = `fp`, oriented along
    /// `t_old`.
    pub(super) fn tangent(
        m: &DMatrix<f64>,
        fp: &DVector<f64>,
        t_old: &DVector<f64>,
    ) -> Result<DVector<f64>, SimError> {
        let dim = m.nrows();
        let mut rhs = DVector::zeros(dim + 1);
        rhs[dim] = 1.0;
        let t = Self::bordered(m, fp, t_old)
            .lu()
            .solve(&rhs)
            .ok_or(SimError::NoConvergence {
                what: "continuation tangent",
                iterations: 0,
                residual: f64::NAN,
            })?;
        Ok(t.normalize())
    }

    /// Newton corrector from the predictor; returns the converged y, its map, the iterations
    /// and ∂F/∂p at the last iterate (reused for the next tangent).
    #[allow(clippy::type_complexity)]
    pub(super) fn correct(
        &mut self,
        y_pred: &DVector<f64>,
        t: &DVector<f64>,
    ) -> Result<(DVector<f64>, FlowMap, usize, DVector<f64>), SimError> {
        let dim = y_pred.len() - 1;
        let mut y = y_pred.clone();
        // ∂F/∂p of the previous iterate (finite differences are not redone at convergence)
        let mut fp_prev: Option<DVector<f64>> = None;
        // the iterates skip the grazing searches (a fifth of a map) except the one expected to
        // converge, after a correction that Newton's quadratic rate makes the last; the
        // converged point gets its distance to grazing from one pass otherwise
        let mut last_delta = f64::INFINITY;
        for it in 0..10 {
            let (z, p) = (y.rows(0, dim).into_owned(), y[dim]);
            let watched = last_delta <= 1e-7 * (1.0 + y.norm());
            let mut map = self.map(&z, p, watched)?;
            let f = &map.state - &z;
            let arc = t.dot(&(&y - y_pred));
            let res = f.norm();
            if res <= self.spec.newton.tol * (1.0 + z.norm())
                && arc.abs() <= 1e-12 * (1.0 + y.norm())
            {
                if !watched {
                    map.grazing_distance = self.grazing(&z, p)?;
                }
                let fp = match (&map.param_derivative, fp_prev) {
                    (Some(d), _) => d.clone(),
                    (None, Some(fp)) => fp,
                    (None, None) => self.dp(&z, p)?,
                };
                return Ok((y, map, it, fp));
            }
            let fp = self.dp_of(&map, &z, p)?;
            let mut g = DVector::zeros(dim + 1);
            g.rows_mut(0, dim).copy_from(&f);
            g[dim] = arc;
            let delta = Self::bordered(&map.jacobian, &fp, t)
                .lu()
                .solve(&(-g))
                .ok_or(SimError::NoConvergence {
                    what: "continuation corrector",
                    iterations: it,
                    residual: res,
                })?;
            last_delta = delta.norm();
            y += delta;
            fp_prev = Some(fp);
            if !y.iter().all(|v| v.is_finite()) {
                break;
            }
        }
        Err(SimError::NoConvergence {
            what: "continuation corrector",
            iterations: 10,
            residual: f64::NAN,
        })
    }
}
