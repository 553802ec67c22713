//! A recorded bag as a stream of [`SessionInput`]s, read lazily: messages are decoded by
//! their type on the configured topics; anything else is counted and skipped, and a
//! message that does not decode is counted with its reason. Fixes are joined with the
//! velocities of their stamps by the live node's code ([`FixVelocityJoin`]), driven by the
//! bag's message order and IMU time as the node is by arrival order and IMU time.

use std::collections::{BTreeMap, VecDeque};

use nalgebra::Matrix3;

use crate::earth::{self, Llh};
use crate::engine::GnssFix;
use crate::eval::TruthSample;
use crate::gnss::{Constellation, GnssEpoch, SatId};
use crate::ins::ImuSample;
use crate::ros::bag::BagMessages;
use crate::ros::cdr;
use crate::ros::convert::{time_to_seconds, GnssVelocity};
use crate::ros::fix_velocity::{FixVelocityJoin, FramedFix, Joined, VelocityUse};
use crate::ros::msg::{
    DiagnosticArray, GnssMeasurements, Imu, NavSatFix, NoiseEstimates, Odometry, RosMessage,
    TwistWithCovarianceStamped,
};

use super::session::SessionInput;

/// Which topic carries what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BagTopics {
    pub imu: String,
    pub gnss: String,
    pub fix: String,
    /// geometry_msgs/TwistWithCovarianceStamped receiver velocities, joined with the fix of
    /// their stamp.
    pub velocity: String,
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
            velocity: VELOCITY_TOPIC.to_owned(),
            truth: Some(TRUTH_TOPIC.to_owned()),
            truth_datum: TRUTH_DATUM_TOPIC.to_owned(),
            truth_noise: TRUTH_NOISE_TOPIC.to_owned(),
            environment: TRUTH_ENVIRONMENT_TOPIC.to_owned(),
        }
    }
}

/// What was read and what was skipped while reading.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ReadProblems {
    /// Messages used (decoded and handed on, or the datum), by topic.
    pub used_topics: BTreeMap<String, u64>,
    /// Messages on topics this run does not use, by "topic (type)".
    pub unused_topics: BTreeMap<String, u64>,
    /// Messages on a topic this run uses but of another type, by "topic: type, expected
    /// type".
    pub wrong_types: BTreeMap<String, u64>,
    /// Messages that did not decode or convert, by "topic: reason".
    pub undecodable: BTreeMap<String, u64>,
    /// Errors of the bag itself (corrupt chunks, truncation).
    pub bag_errors: Vec<String>,
    /// What became of the velocities.
    pub velocities: VelocityCounts,
}

/// What became of the receiver velocities of a bag (counted as the node counts them).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct VelocityCounts {
    /// Joined with the fix of their stamp.
    pub paired: u64,
    /// Dropped for want of a fix of their stamp.
    pub unpaired: u64,
    /// Paired but in a frame neither [`REPLAY_MAP_FRAME`] nor their fix's: not used.
    pub foreign_frame: u64,
}

/// The ENU frame a velocity of a bag may be given in (besides its fix's frame): the frame
/// of the replay's Odometry, as the node's default `map_frame`.
pub const REPLAY_MAP_FRAME: &str = "map";

impl ReadProblems {
    /// Messages used on `topic`.
    pub fn used(&self, topic: &str) -> u64 {
        self.used_topics.get(topic).copied().unwrap_or(0)
    }

    /// Messages skipped for any reason (bag errors are not messages and not counted).
    pub fn skipped(&self) -> u64 {
        self.unused_topics.values().sum::<u64>()
            + self.wrong_types.values().sum::<u64>()
            + self.undecodable.values().sum::<u64>()
    }
}

impl BagTopics {
    /// The message type this run expects on `topic`, if it uses the topic.
    pub fn expected_type(&self, topic: &str) -> Option<&'static str> {
        if topic == self.imu {
            Some(Imu::TYPE_NAME)
        } else if topic == self.gnss {
            Some(GnssMeasurements::TYPE_NAME)
        } else if topic == self.fix || topic == self.truth_datum {
            Some(NavSatFix::TYPE_NAME)
        } else if topic == self.velocity {
            Some(TwistWithCovarianceStamped::TYPE_NAME)
        } else if self.truth.as_deref() == Some(topic) {
            Some(Odometry::TYPE_NAME)
        } else if topic == self.truth_noise {
            Some(NoiseEstimates::TYPE_NAME)
        } else if topic == self.environment {
            Some(DiagnosticArray::TYPE_NAME)
        } else {
            None
        }
    }
}

/// The iterator of inputs over a bag's messages.
pub struct BagInputs {
    messages: BagMessages,
    topics: BagTopics,
    datum: Option<Llh>,
    problems: ReadProblems,
    join: FixVelocityJoin,
    /// Inputs of the last message, not yet handed on.
    ready: VecDeque<SessionInput>,
}

impl BagInputs {
    pub fn new(messages: BagMessages, topics: BagTopics) -> Self {
        Self {
            messages,
            topics,
            datum: None,
            problems: ReadProblems::default(),
            join: FixVelocityJoin::new(REPLAY_MAP_FRAME),
            ready: VecDeque::new(),
        }
    }

    /// What was read and skipped so far.
    pub fn problems(&self) -> ReadProblems {
        let mut problems = self.problems.clone();
        problems.velocities.unpaired = self.join.unpaired_velocities();
        problems
    }

    /// Queues joined fixes as inputs, counting what became of their velocities.
    fn queue_fixes(&mut self, joined: Vec<Joined>) {
        for j in joined {
            let counts = &mut self.problems.velocities;
            match j.velocity {
                VelocityUse::None => {}
                VelocityUse::Paired => counts.paired += 1,
                VelocityUse::ForeignFrame(_) => counts.foreign_frame += 1,
            }
            self.ready.push_back(SessionInput::Fix(j.fix));
        }
    }

    /// Counts one message of `topic` in `map` under `key`.
    fn count(map: &mut BTreeMap<String, u64>, key: String) {
        *map.entry(key).or_insert(0) += 1;
    }

    /// Queues the inputs of one message; counts it as used or skipped (with the reason).
    fn convert(&mut self, topic: &str, type_name: &str, data: &[u8]) {
        let problems = &mut self.problems;
        match self.topics.expected_type(topic) {
            None => {
                Self::count(
                    &mut problems.unused_topics,
                    format!("{topic} ({type_name})"),
                );
            }
            Some(expected) if expected != type_name => {
                Self::count(
                    &mut problems.wrong_types,
                    format!("{topic}: {type_name}, expected {expected}"),
                );
            }
            Some(_) => match self.convert_known(topic, data) {
                Ok(()) => {
                    // Choice: the count lookup by &str first avoids an allocation per
                    // message on the hot path (hundreds of thousands of IMU samples).
                    match self.problems.used_topics.get_mut(topic) {
                        Some(n) => *n += 1,
                        None => {
                            self.problems.used_topics.insert(topic.to_owned(), 1);
                        }
                    }
                }
                Err(reason) => {
                    Self::count(&mut self.problems.undecodable, format!("{topic}: {reason}"));
                }
            },
        }
    }

    /// Queues the inputs of a message of the expected type on a topic this run uses (none
    /// for the datum, a fix without solution, a fix or velocity still waiting for its
    /// partner); Err with the reason for one that does not decode or convert.
    fn convert_known(&mut self, topic: &str, data: &[u8]) -> Result<(), String> {
        let input = self.input_of(topic, data)?;
        self.ready.extend(input);
        Ok(())
    }

    /// The input of a message that gives at most one on its own (fixes and velocities are
    /// queued through the join).
    fn input_of(&mut self, topic: &str, data: &[u8]) -> Result<Option<SessionInput>, String> {
        let t = &self.topics;
        let stamp = |s: &crate::ros::msg::Time| time_to_seconds(s).map_err(|e| e.to_string());
        if topic == t.imu {
            let msg: Imu = decode(data)?;
            let sample = ImuSample::try_from(&msg).map_err(|e| e.to_string())?;
            // As the node: fixes that waited long enough go before this sample.
            let joined = self.join.on_time(sample.t_s);
            self.queue_fixes(joined);
            return Ok(Some(SessionInput::Imu(sample)));
        }
        if topic == t.gnss {
            let msg: GnssMeasurements = decode(data)?;
            let epoch = GnssEpoch::try_from(&msg).map_err(|e| e.to_string())?;
            return Ok(Some(SessionInput::Gnss(epoch)));
        }
        if topic == t.fix {
            let msg: NavSatFix = decode(data)?;
            if msg.status.status < 0 {
                return Ok(None);
            }
            let fix = FramedFix {
                fix: fix_of(&msg, stamp(&msg.header.stamp)?),
                frame_id: msg.header.frame_id,
            };
            let joined = self.join.on_fix(fix);
            self.queue_fixes(joined);
            return Ok(None);
        }
        if topic == t.velocity {
            let msg: TwistWithCovarianceStamped = decode(data)?;
            let velocity = GnssVelocity::try_from(&msg).map_err(|e| e.to_string())?;
            let joined = self.join.on_velocity(velocity);
            self.queue_fixes(joined);
            return Ok(None);
        }
        if topic == t.truth_datum {
            let msg: NavSatFix = decode(data)?;
            self.datum = Some(Llh::from_degrees(msg.latitude, msg.longitude, msg.altitude));
            return Ok(None);
        }
        if t.truth.as_deref() == Some(topic) {
            let msg: Odometry = decode(data)?;
            let datum = self.datum.ok_or("reference before its datum")?;
            let t_s = stamp(&msg.header.stamp)?;
            let truth = truth_of(&msg, t_s, &datum).ok_or("reference position out of range")?;
            return Ok(Some(SessionInput::Truth(truth)));
        }
        if topic == t.truth_noise {
            let msg: NoiseEstimates = decode(data)?;
            let t_s = stamp(&msg.header.stamp)?;
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
            return Ok(Some(SessionInput::TruthSigmas { t_s, sigmas }));
        }
        if topic == t.environment {
            let msg: DiagnosticArray = decode(data)?;
            let t_s = stamp(&msg.header.stamp)?;
            let name = msg
                .status
                .first()
                .ok_or("environment without status")?
                .message
                .clone();
            return Ok(Some(SessionInput::Environment { t_s, name }));
        }
        Ok(None)
    }
}

/// Decodes CDR, the error as text.
fn decode<T: RosMessage>(data: &[u8]) -> Result<T, String> {
    cdr::decode::<T>(data).map_err(|e| e.to_string())
}

impl Iterator for BagInputs {
    type Item = SessionInput;

    fn next(&mut self) -> Option<SessionInput> {
        loop {
            if let Some(input) = self.ready.pop_front() {
                return Some(input);
            }
            match self.messages.next()? {
                Ok(m) => self.convert(&m.topic, &m.type_name, &m.data),
                Err(e) => self.problems.bag_errors.push(e.to_string()),
            }
        }
    }
}

/// A receiver fix from a NavSatFix with a solution, stamped `t_s`.
pub(crate) fn fix_of(msg: &NavSatFix, t_s: f64) -> GnssFix {
    let c = &msg.position_covariance;
    let covariance = (msg.position_covariance_type != NavSatFix::COVARIANCE_TYPE_UNKNOWN)
        .then(|| Matrix3::from_fn(|r, k| c[3 * r + k]));
    GnssFix {
        t_s,
        position: Llh::from_degrees(msg.latitude, msg.longitude, msg.altitude),
        position_covariance_enu_m2: covariance,
        velocity_enu_mps: None,
        velocity_covariance_enu_m2_s2: None,
    }
}

/// A reference sample at `t_s` from Odometry in the ENU frame at `datum` (None when the
/// position does not convert).
///
/// A reference without attitude (a GNSS trajectory, as `convert` writes) has the all-zero
/// quaternion; its twist is then in the pose's own frame (`child_frame_id` equal to
/// `header.frame_id`: the ENU velocity). A twist whose covariance starts with −1 is not
/// provided.
fn truth_of(msg: &Odometry, t_s: f64, datum: &Llh) -> Option<TruthSample> {
    let p = &msg.pose.pose.position;
    let llh = earth::enu_to_llh(&nalgebra::Vector3::new(p.x, p.y, p.z), datum)?;
    let o = &msg.pose.pose.orientation;
    let q = nalgebra::Quaternion::new(o.w, o.x, o.y, o.z);
    let q_nb = (q.norm() > 0.0).then(|| nalgebra::UnitQuaternion::from_quaternion(q));
    let v = &msg.twist.twist.linear;
    let v = nalgebra::Vector3::new(v.x, v.y, v.z);
    let v_n = if msg.twist.covariance[0] < 0.0 {
        None
    } else if msg.child_frame_id == msg.header.frame_id {
        Some(v)
    } else {
        q_nb.map(|q| q * v)
    };
    Some(TruthSample {
        t_s,
        p: llh,
        v_n,
        q_nb,
    })
}
