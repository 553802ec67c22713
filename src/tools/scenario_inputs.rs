//! A simulated scenario as session inputs, without a bag in between (the same messages a
//! bag written by `simulate` carries, minus the CDR round trip).

use crate::eval::TruthSample;
use crate::sim::{Scenario, ScenarioError, SimEvent};

use super::scoring::Reference;
use super::session::SessionInput;

/// The inputs of `scenario`, in time order (the true σ of an epoch just before it); a
/// generator error ends the stream with it.
pub fn scenario_inputs(
    scenario: &Scenario,
) -> impl Iterator<Item = Result<SessionInput, ScenarioError>> + '_ {
    scenario.events().flat_map(|event| {
        let inputs = match event {
            Err(e) => vec![Err(e)],
            Ok(SimEvent::Imu(s)) => vec![Ok(SessionInput::Imu(s))],
            Ok(SimEvent::Truth(t)) => {
                vec![Ok(SessionInput::Reference(Reference::Truth(
                    TruthSample::from(&t.nav),
                )))]
            }
            Ok(SimEvent::Environment { t_s, name, .. }) => {
                vec![Ok(SessionInput::Reference(Reference::Environment {
                    t_s,
                    name: name.to_owned(),
                }))]
            }
            Ok(SimEvent::Gnss {
                epoch,
                truth_sigmas,
                ..
            }) => vec![
                Ok(SessionInput::Reference(Reference::TruthSigmas {
                    t_s: epoch.t_s,
                    sigmas: truth_sigmas,
                })),
                Ok(SessionInput::Gnss(epoch)),
            ],
            Ok(SimEvent::Fix(f)) => vec![Ok(SessionInput::Fix(f))],
            Ok(SimEvent::BaselineHeading(h)) => vec![Ok(SessionInput::BaselineHeading(h))],
        };
        inputs.into_iter()
    })
}
