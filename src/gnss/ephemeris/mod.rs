//! Broadcast ephemerides: satellite position, velocity and clock at transmission time
//! from the Keplerian elements of GPS LNAV, QZSS LNAV, Galileo I/NAV and F/NAV and
//! BeiDou D1/D2 (GLONASS is not handled), a store that picks the right set by time and
//! health, and the filling of [`crate::gnss::SatObservation`]'s satellite fields.
//! No I/O: decoders (`crate::gnss::ubx`, `crate::gnss::rinex_nav`) produce the elements.

mod kepler;
mod ranging;
mod signal;
mod store;
mod time;
mod transmit;

pub use kepler::{
    GroupDelay, KeplerianEphemeris, NavSource, SatState, SystemConstants, BEIDOU_CONSTANTS,
    GALILEO_CONSTANTS, GPS_CONSTANTS,
};
pub use ranging::{iono_free_coefficients, RangingCode};
pub use signal::{group_delay_s, Signal};
pub use store::{EphemerisStore, InsertOutcome, MAX_EPHEMERIDES_PER_SAT};
pub use time::{
    resolve_week, GpsTime, BDT_MINUS_GPST_S, BDT_WEEK_OFFSET, GST_WEEK_OFFSET, SECONDS_PER_WEEK,
};
pub use transmit::{fill_satellite_fields, state_at_transmission, EphemerisError, TransmitState};
