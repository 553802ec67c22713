//! The event sources every node's loop has besides its inputs.

use futures::stream::{LocalBoxStream, StreamExt};

use super::dds::DIAGNOSTICS_PERIOD;
use super::rosout::{LogLine, LogLines};
use super::services::{ParamRequest, ParameterServices};

/// What wraps each housekeeping event of a node's loop.
pub struct Housekeeping<E> {
    /// A tick every [`DIAGNOSTICS_PERIOD`].
    pub tick: fn() -> E,
    /// A parameter service request.
    pub param: fn(ParamRequest) -> E,
    /// A log line for `/rosout`.
    pub log_line: fn(LogLine) -> E,
    /// SIGINT or SIGTERM.
    pub stop: fn() -> E,
}

/// The event sources every node has besides its inputs: the diagnostics tick, the
/// requests of `services`, the `log_lines` for `/rosout` and the stop signals (so that
/// the loop ends and a recording is completed; without a handler the process would die
/// with the bag unfinished).
pub fn housekeeping<'a, E: 'a>(
    services: &'a ParameterServices,
    log_lines: Option<LogLines>,
    wrap: Housekeeping<E>,
) -> Vec<LocalBoxStream<'a, E>> {
    let mut sources = vec![smol::Timer::interval(DIAGNOSTICS_PERIOD)
        .map(move |_| (wrap.tick)())
        .boxed_local()];
    sources.extend(
        services
            .streams()
            .into_iter()
            .map(|s| s.map(wrap.param).boxed_local()),
    );
    if let Some(lines) = log_lines {
        sources.push(lines.map(wrap.log_line).boxed_local());
    }
    match async_signal::Signals::new([async_signal::Signal::Int, async_signal::Signal::Term]) {
        Ok(signals) => sources.push(signals.map(move |_| (wrap.stop)()).boxed_local()),
        Err(e) => log::warn!("cannot handle SIGINT/SIGTERM ({e}); stopping kills the node"),
    }
    sources
}
