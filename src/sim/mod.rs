//! Simulation: scenario ingredients that stand in for the real world in tests and
//! benchmarks (deterministic; no I/O).

pub mod constellation;
