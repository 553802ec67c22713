//! A recorded bag as a stream of decoded messages, read lazily: the messages on the input
//! topics a run feeds go to the ROS adapter as DDS hands them to the node, the reference
//! topics to the scoring. Anything else is counted and skipped, and a message that does
//! not decode is counted with its reason.

use std::collections::BTreeMap;

use crate::earth::{self, Llh};
use crate::eval::TruthSample;
use crate::gnss::{Constellation, SatId};
use crate::ros::adapter::{Input, InputMessage};
use crate::ros::bag::BagMessages;
use crate::ros::cdr;
use crate::ros::convert::time_to_seconds;
use crate::ros::msg::{
    DiagnosticArray, GnssMeasurements, Imu, NavSatFix, NoiseEstimates, Odometry, RosMessage,
    TFMessage, TwistWithCovarianceStamped, UbxNavRelPosNed,
};

use super::scoring::Reference;

/// The node's wheel odometry topic (`wheel/odometry` in the root namespace): the simulator
/// writes none.
pub const WHEEL_ODOMETRY_TOPIC: &str = "/wheel/odometry";

/// Which topic carries what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BagTopics {
    pub imu: String,
    pub gnss: String,
    pub fix: String,
    /// geometry_msgs/TwistWithCovarianceStamped receiver velocities, joined with the fix of
    /// their stamp.
    pub velocity: String,
    /// nav_msgs/Odometry of the base controller, whose forward speed is fed with
    /// `wheel_odometry.enabled`.
    pub wheel_odometry: String,
    /// tf2_msgs/TFMessage with the base controller's `odom_frame → base_frame`, read only
    /// when the run publishes `map → odom` (`tf_mode` `map_to_odom`, as the node then
    /// subscribes `/tf`); None: not read.
    pub tf: Option<String>,
    /// ublox_ubx_msgs/UBXNavRelPosNED of a moving-base pair, whose baseline heading is fed
    /// with `dual_antenna.enabled`.
    pub rel_pos_ned: String,
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
            wheel_odometry: WHEEL_ODOMETRY_TOPIC.to_owned(),
            tf: None,
            rel_pos_ned: REL_POS_NED_TOPIC.to_owned(),
            truth: Some(TRUTH_TOPIC.to_owned()),
            truth_datum: TRUTH_DATUM_TOPIC.to_owned(),
            truth_noise: TRUTH_NOISE_TOPIC.to_owned(),
            environment: TRUTH_ENVIRONMENT_TOPIC.to_owned(),
        }
    }
}

/// What a topic of the bag is to a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    Input(Input),
    /// The base controller's `/tf`, for the adapter's `map → odom`.
    Tf,
    TruthDatum,
    Truth,
    TruthNoise,
    Environment,
}

impl Role {
    fn type_name(self) -> &'static str {
        match self {
            Role::Input(Input::Imu) => Imu::TYPE_NAME,
            Role::Input(Input::Gnss) => GnssMeasurements::TYPE_NAME,
            Role::Input(Input::Fix) | Role::TruthDatum => NavSatFix::TYPE_NAME,
            Role::Input(Input::Velocity) => TwistWithCovarianceStamped::TYPE_NAME,
            Role::Input(Input::WheelOdometry) | Role::Truth => Odometry::TYPE_NAME,
            Role::Tf => TFMessage::TYPE_NAME,
            Role::Input(Input::RelPosNed) => UbxNavRelPosNed::TYPE_NAME,
            Role::TruthNoise => NoiseEstimates::TYPE_NAME,
            Role::Environment => DiagnosticArray::TYPE_NAME,
        }
    }
}

impl BagTopics {
    /// The role of `topic` in a run, if it has one.
    fn role(&self, topic: &str) -> Option<Role> {
        if topic == self.imu {
            Some(Role::Input(Input::Imu))
        } else if topic == self.gnss {
            Some(Role::Input(Input::Gnss))
        } else if topic == self.fix {
            Some(Role::Input(Input::Fix))
        } else if topic == self.velocity {
            Some(Role::Input(Input::Velocity))
        } else if topic == self.wheel_odometry {
            Some(Role::Input(Input::WheelOdometry))
        } else if self.tf.as_deref() == Some(topic) {
            Some(Role::Tf)
        } else if topic == self.rel_pos_ned {
            Some(Role::Input(Input::RelPosNed))
        } else if topic == self.truth_datum {
            Some(Role::TruthDatum)
        } else if self.truth.as_deref() == Some(topic) {
            Some(Role::Truth)
        } else if topic == self.truth_noise {
            Some(Role::TruthNoise)
        } else if topic == self.environment {
            Some(Role::Environment)
        } else {
            None
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
    /// Messages on an input topic this run does not feed (the other coupling's), by topic.
    pub unfed_inputs: BTreeMap<String, u64>,
    /// Messages on a topic this run uses but of another type, by "topic: type, expected
    /// type".
    pub wrong_types: BTreeMap<String, u64>,
    /// Messages that did not decode or convert, by "topic: reason".
    pub undecodable: BTreeMap<String, u64>,
    /// Errors of the bag itself (corrupt chunks, truncation).
    pub bag_errors: Vec<String>,
}

impl ReadProblems {
    /// Messages used on `topic`.
    pub fn used(&self, topic: &str) -> u64 {
        self.used_topics.get(topic).copied().unwrap_or(0)
    }

    /// Messages skipped for any reason (bag errors are not messages and not counted).
    pub fn skipped(&self) -> u64 {
        self.unused_topics.values().sum::<u64>()
            + self.unfed_inputs.values().sum::<u64>()
            + self.wrong_types.values().sum::<u64>()
            + self.undecodable.values().sum::<u64>()
    }
}

/// One item of a bag for a run.
///
/// Choice: the message is not boxed: nearly every item is one, and a box would cost an
/// allocation per message to shrink the rare references.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
pub enum BagInput {
    /// A message for the adapter.
    Message(InputMessage),
    /// A `/tf` message for the adapter
    /// ([`RosAdapter::on_tf`](crate::ros::adapter::RosAdapter::on_tf)).
    Tf(TFMessage),
    /// A message on an input topic or `/tf` that did not decode (the adapter counts it, as
    /// the node counts an undecodable payload).
    Undecodable { topic: String, error: String },
    /// A reference for the scoring.
    Reference(Reference),
}

/// The iterator of [`BagInput`]s over a bag's messages.
pub struct BagInputs {
    messages: BagMessages,
    topics: BagTopics,
    /// The input streams fed (the others' messages are counted as unfed).
    fed: Vec<Input>,
    datum: Option<Llh>,
    problems: ReadProblems,
    /// Messages read so far (for progress).
    read: u64,
}

/// Counts one message under `key`.
fn count(map: &mut BTreeMap<String, u64>, key: String) {
    *map.entry(key).or_insert(0) += 1;
}

impl BagInputs {
    /// The items of `messages` with the topics `topics`, feeding the input streams `fed`.
    pub fn new(messages: BagMessages, topics: BagTopics, fed: &[Input]) -> Self {
        Self {
            messages,
            topics,
            fed: fed.to_vec(),
            datum: None,
            problems: ReadProblems::default(),
            read: 0,
        }
    }

    /// What was read and skipped so far.
    pub fn problems(&self) -> &ReadProblems {
        &self.problems
    }

    /// Messages read so far.
    pub fn messages_read(&self) -> u64 {
        self.read
    }

    /// The item of one message, if it gives one; counts it as used or skipped (with the
    /// reason).
    fn item(&mut self, topic: &str, type_name: &str, data: &[u8]) -> Option<BagInput> {
        let Some(role) = self.topics.role(topic) else {
            count(
                &mut self.problems.unused_topics,
                format!("{topic} ({type_name})"),
            );
            return None;
        };
        if role.type_name() != type_name {
            count(
                &mut self.problems.wrong_types,
                format!("{topic}: {type_name}, expected {}", role.type_name()),
            );
            return None;
        }
        if matches!(role, Role::Input(input) if !self.fed.contains(&input)) {
            count(&mut self.problems.unfed_inputs, topic.to_owned());
            return None;
        }
        match self.decoded(role, data) {
            Ok(item) => {
                // Choice: the count lookup by &str first avoids an allocation per
                // message on the hot path (hundreds of thousands of IMU samples).
                match self.problems.used_topics.get_mut(topic) {
                    Some(n) => *n += 1,
                    None => {
                        self.problems.used_topics.insert(topic.to_owned(), 1);
                    }
                }
                item
            }
            Err(error) => {
                count(&mut self.problems.undecodable, format!("{topic}: {error}"));
                matches!(role, Role::Input(_) | Role::Tf).then(|| BagInput::Undecodable {
                    topic: topic.to_owned(),
                    error,
                })
            }
        }
    }

    /// The item of a message of the expected type on a topic this run uses (none for the
    /// datum); Err with the reason for one that does not decode, or a reference that does
    /// not convert.
    fn decoded(&mut self, role: Role, data: &[u8]) -> Result<Option<BagInput>, String> {
        let stamp = |s: &crate::ros::msg::Time| time_to_seconds(s).map_err(|e| e.to_string());
        let message = match role {
            Role::Input(Input::Imu) => InputMessage::Imu(decode(data)?),
            Role::Input(Input::Gnss) => InputMessage::Gnss(decode(data)?),
            Role::Input(Input::Fix) => InputMessage::Fix(decode(data)?),
            Role::Input(Input::Velocity) => InputMessage::Velocity(decode(data)?),
            Role::Input(Input::WheelOdometry) => {
                InputMessage::WheelOdometry(Box::new(decode(data)?))
            }
            Role::Tf => return Ok(Some(BagInput::Tf(decode(data)?))),
            Role::Input(Input::RelPosNed) => InputMessage::RelPosNed(Box::new(decode(data)?)),
            Role::TruthDatum => {
                let msg: NavSatFix = decode(data)?;
                self.datum = Some(Llh::from_degrees(msg.latitude, msg.longitude, msg.altitude));
                return Ok(None);
            }
            Role::Truth => {
                let msg: Odometry = decode(data)?;
                let datum = self.datum.ok_or("reference before its datum")?;
                let t_s = stamp(&msg.header.stamp)?;
                let truth = truth_of(&msg, t_s, &datum).ok_or("reference position out of range")?;
                return Ok(Some(BagInput::Reference(Reference::Truth(truth))));
            }
            Role::TruthNoise => {
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
                return Ok(Some(BagInput::Reference(Reference::TruthSigmas {
                    t_s,
                    sigmas,
                })));
            }
            Role::Environment => {
                let msg: DiagnosticArray = decode(data)?;
                let t_s = stamp(&msg.header.stamp)?;
                let name = msg
                    .status
                    .first()
                    .ok_or("environment without status")?
                    .message
                    .clone();
                return Ok(Some(BagInput::Reference(Reference::Environment {
                    t_s,
                    name,
                })));
            }
        };
        Ok(Some(BagInput::Message(message)))
    }
}

/// Decodes CDR, the error as text.
fn decode<T: RosMessage>(data: &[u8]) -> Result<T, String> {
    cdr::decode::<T>(data).map_err(|e| e.to_string())
}

impl Iterator for BagInputs {
    type Item = BagInput;

    fn next(&mut self) -> Option<BagInput> {
        loop {
            match self.messages.next()? {
                Ok(m) => {
                    self.read += 1;
                    if let Some(item) = self.item(&m.topic, &m.type_name, &m.data) {
                        return Some(item);
                    }
                }
                Err(e) => self.problems.bag_errors.push(e.to_string()),
            }
        }
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
