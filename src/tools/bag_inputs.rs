//! A recorded bag as a stream of [`SessionInput`]s, read lazily: messages are decoded by
//! their type on the configured topics; anything else is counted and skipped, and a
//! message that does not decode is counted with its reason.

use std::collections::BTreeMap;

use nalgebra::Matrix3;

use crate::earth::{self, Llh};
use crate::engine::GnssFix;
use crate::eval::TruthSample;
use crate::gnss::{Constellation, GnssEpoch, SatId};
use crate::ins::ImuSample;
use crate::ros::bag::BagMessages;
use crate::ros::cdr;
use crate::ros::convert::time_to_seconds;
use crate::ros::msg::{
    DiagnosticArray, GnssMeasurements, Imu, NavSatFix, NoiseEstimates, Odometry, RosMessage,
};

use super::session::SessionInput;

/// Which topic carries what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BagTopics {
    pub imu: String,
    pub gnss: String,
    pub fix: String,
    /// nav_msgs/Odometry reference in an ENU frame at `truth_datum` (None: no reference).
    pub truth: Option<String>,
    pub truth_datum: String,
    pub truth_noise: String,
    pub environment: String,
}

impl Default for BagTopics {
    fn default() -> Self {
        use super::simulate::*;
        Self {
            imu: IMU_TOPIC.to_owned(),
            gnss: GNSS_TOPIC.to_owned(),
            fix: FIX_TOPIC.to_owned(),
            truth: Some(TRUTH_TOPIC.to_owned()),
            truth_datum: TRUTH_DATUM_TOPIC.to_owned(),
            truth_noise: TRUTH_NOISE_TOPIC.to_owned(),
            environment: TRUTH_ENVIRONMENT_TOPIC.to_owned(),
        }
    }
}

/// What was skipped while reading.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ReadProblems {
    /// Messages on topics this run does not use, by topic.
    pub unused_topics: BTreeMap<String, u64>,
    /// Messages that did not decode or convert, by topic and reason.
    pub undecodable: BTreeMap<String, u64>,
    /// Errors of the bag itself (corrupt chunks, truncation).
    pub bag_errors: Vec<String>,
}

/// The iterator of inputs over a bag's messages.
pub struct BagInputs {
    messages: BagMessages,
    topics: BagTopics,
    datum: Option<Llh>,
    problems: ReadProblems,
}

impl BagInputs {
    pub fn new(messages: BagMessages, topics: BagTopics) -> Self {
        Self {
            messages,
            topics,
            datum: None,
            problems: ReadProblems::default(),
        }
    }

    pub fn problems(&self) -> &ReadProblems {
        &self.problems
    }

    fn undecodable(&mut self, topic: &str, reason: &str) {
        *self
            .problems
            .undecodable
            .entry(format!("{topic}: {reason}"))
            .or_insert(0) += 1;
    }

    fn decode<T: RosMessage>(&mut self, topic: &str, data: &[u8]) -> Option<T> {
        match cdr::decode::<T>(data) {
            Ok(m) => Some(m),
            Err(e) => {
                self.undecodable(topic, &e.to_string());
                None
            }
        }
    }

    fn convert(&mut self, topic: &str, type_name: &str, data: &[u8]) -> Option<SessionInput> {
        let t = &self.topics;
        if topic == t.imu && type_name == Imu::TYPE_NAME {
            let msg: Imu = self.decode(topic, data)?;
            return match ImuSample::try_from(&msg) {
                Ok(s) => Some(SessionInput::Imu(s)),
                Err(e) => {
                    self.undecodable(topic, &e.to_string());
                    None
                }
            };
        }
        if topic == t.gnss && type_name == GnssMeasurements::TYPE_NAME {
            let msg: GnssMeasurements = self.decode(topic, data)?;
            return match GnssEpoch::try_from(&msg) {
                Ok(e) => Some(SessionInput::Gnss(e)),
                Err(e) => {
                    self.undecodable(topic, &e.to_string());
                    None
                }
            };
        }
        if topic == t.fix && type_name == NavSatFix::TYPE_NAME {
            let msg: NavSatFix = self.decode(topic, data)?;
            return fix_of(&msg).map(SessionInput::Fix);
        }
        if topic == t.truth_datum && type_name == NavSatFix::TYPE_NAME {
            let msg: NavSatFix = self.decode(topic, data)?;
            self.datum = Some(Llh::from_degrees(msg.latitude, msg.longitude, msg.altitude));
            return None;
        }
        if t.truth.as_deref() == Some(topic) && type_name == Odometry::TYPE_NAME {
            let msg: Odometry = self.decode(topic, data)?;
            let Some(datum) = self.datum else {
                self.undecodable(topic, "reference before its datum");
                return None;
            };
            return truth_of(&msg, &datum).map(SessionInput::Truth);
        }
        if topic == t.truth_noise && type_name == NoiseEstimates::TYPE_NAME {
            let msg: NoiseEstimates = self.decode(topic, data)?;
            let t_s = time_to_seconds(&msg.header.stamp).ok()?;
            let sigmas = msg
                .satellites
                .iter()
                .filter_map(|s| {
                    let sat = SatId {
                        constellation: Constellation::from_code(s.constellation)?,
                        prn: s.prn,
                    };
                    Some((
                        sat,
                        s.r_pseudorange_m2.sqrt(),
                        s.r_pseudorange_rate_m2_s2.sqrt(),
                    ))
                })
                .collect();
            return Some(SessionInput::TruthSigmas { t_s, sigmas });
        }
        if topic == t.environment && type_name == DiagnosticArray::TYPE_NAME {
            let msg: DiagnosticArray = self.decode(topic, data)?;
            let t_s = time_to_seconds(&msg.header.stamp).ok()?;
            let name = msg.status.first()?.message.clone();
            return Some(SessionInput::Environment { t_s, name });
        }
        *self
            .problems
            .unused_topics
            .entry(topic.to_owned())
            .or_insert(0) += 1;
        None
    }
}

impl Iterator for BagInputs {
    type Item = SessionInput;

    fn next(&mut self) -> Option<SessionInput> {
        loop {
            match self.messages.next()? {
                Ok(m) => {
                    if let Some(input) = self.convert(&m.topic, &m.type_name, &m.data) {
                        return Some(input);
                    }
                }
                Err(e) => self.problems.bag_errors.push(e.to_string()),
            }
        }
    }
}

/// A receiver fix from NavSatFix (a fix without a solution is skipped).
pub(crate) fn fix_of(msg: &NavSatFix) -> Option<GnssFix> {
    if msg.status.status < 0 {
        return None;
    }
    let t_s = time_to_seconds(&msg.header.stamp).ok()?;
    let c = &msg.position_covariance;
    let covariance = (msg.position_covariance_type != NavSatFix::COVARIANCE_TYPE_UNKNOWN)
        .then(|| Matrix3::from_fn(|r, k| c[3 * r + k]));
    Some(GnssFix {
        t_s,
        position: Llh::from_degrees(msg.latitude, msg.longitude, msg.altitude),
        position_covariance_enu_m2: covariance,
        velocity_enu_mps: None,
        velocity_covariance_enu_m2_s2: None,
    })
}

/// A reference sample from Odometry in the ENU frame at `datum`.
fn truth_of(msg: &Odometry, datum: &Llh) -> Option<TruthSample> {
    let t_s = time_to_seconds(&msg.header.stamp).ok()?;
    let p = &msg.pose.pose.position;
    let llh = earth::enu_to_llh(&nalgebra::Vector3::new(p.x, p.y, p.z), datum)?;
    let o = &msg.pose.pose.orientation;
    let q_nb =
        nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(o.w, o.x, o.y, o.z));
    let v = &msg.twist.twist.linear;
    let v_n = q_nb * nalgebra::Vector3::new(v.x, v.y, v.z);
    Some(TruthSample {
        t_s,
        p: llh,
        v_n: Some(v_n),
        q_nb: Some(q_nb),
    })
}
