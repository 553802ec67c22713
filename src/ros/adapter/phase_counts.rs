//! What the time-differenced carrier-phase updates (`gnss.tdcp`) did with the satellites'
//! phase changes, summed over the epoch reports for /diagnostics: a stream of slipping
//! phases, unresolved half cycles or missing wavelengths shows as counts, not only as a
//! filter that never uses its phases.

use std::collections::BTreeMap;

use crate::engine::EpochReport;

/// Phase changes used and left out, by reason (the reason's name).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PhaseCounts {
    /// Phase changes that entered an update.
    pub used: u64,
    /// Phase changes left out, by the name of the reason (a phase reason such as
    /// `cycle_slip`, or one shared with the pseudo-ranges such as `innovation_gate`).
    pub rejected: BTreeMap<&'static str, u64>,
}

impl PhaseCounts {
    /// Adds the carrier-phase part of `report` (nothing without one).
    pub fn add(&mut self, report: &EpochReport) {
        let Some(phases) = &report.carrier_phase_deltas else {
            return;
        };
        for sat in &phases.satellites {
            let reason = sat
                .phase_rejection
                .map(|r| r.name())
                .or(sat.rejection.map(|r| r.name()));
            match (sat.used_pseudorange, reason) {
                (true, _) => self.used += 1,
                (false, Some(name)) => *self.rejected.entry(name).or_default() += 1,
                (false, None) => {}
            }
        }
    }

    /// The counts as /diagnostics keys: `tdcp_phases_used`, `tdcp_rejected_<reason>`.
    pub fn named(&self) -> Vec<(String, u64)> {
        std::iter::once(("tdcp_phases_used".to_owned(), self.used))
            .chain(
                self.rejected
                    .iter()
                    .map(|(name, n)| (format!("tdcp_rejected_{name}"), *n)),
            )
            .collect()
    }
}
