//! Analyses on the stroboscopic Poincaré map: steady states and their periods, parameter
//! sweeps (bifurcation diagrams), coexisting attractors and basins, mode convergence (Fig. 4).

pub mod attractors;
pub mod bifurcation;
pub mod converge;
pub mod period;
pub mod steady;
