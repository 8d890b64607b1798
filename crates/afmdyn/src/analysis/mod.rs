//! Analyses on the stroboscopic Poincaré map: steady states and their periods, parameter
//! sweeps (bifurcation diagrams), coexisting attractors and basins, mode convergence (Fig. 4);
//! beyond the paper: monodromy matrices with saltation, Newton shooting, Floquet multipliers,
//! pseudo-arclength continuation, Lyapunov exponents and the 0–1 test for chaos; the observables
//! of a steady state (harmonics and phase, forces, sample dissipation, virial, energy balances).

pub mod approach;
pub mod attractors;
pub mod bifurcation;
pub mod continuation;
pub mod converge;
pub mod lyapunov;
pub mod monodromy;
pub mod observables;
pub mod period;
pub mod resonance;
pub mod shooting;
pub mod steady;
pub mod stepped;
