//! The `header.frame_id` an input stream is locked to.

/// Messages per window of [`FrameLock`]'s rate count.
///
/// Choice: 500 messages, 5 s of a 100 Hz IMU. A frame that delivers none of them while
/// another frame delivers most of them has gone silent; so recovering from a hijack costs
/// at most a window of the real stream, and a foreign publisher takes over a live stream
/// only by sending more than 500 messages between two of its messages (50 kHz against a
/// 100 Hz IMU). Without a clock nothing tells a flood from a fast sensor: a node that
/// must resist one is given its frame (`imu_frame`). The GNSS and fix streams (1–10 Hz)
/// follow the same rule, so there the window is 50 to 500 s, and no parameter fixes their
/// frame yet.
pub(super) const SWITCH_WINDOW_MESSAGES: u32 = 500;
/// Other frames a window tells apart (more are counted in the window's total only).
const TRACKED_FRAMES: usize = 4;

/// What becomes of a message from a given frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Admission {
    /// Its stream's frame (or no frame is locked yet).
    Admitted,
    /// Its stream's new frame: the locked one went silent and this one took over.
    Switched,
    /// Another frame than the locked one: dropped.
    Foreign,
}

/// The `header.frame_id` a stream is locked to.
///
/// Choice: the frame is either configured (only it is admitted, ever) or learnt: the first
/// message the engine accepts locks its frame, messages from any other frame are counted
/// and dropped, and the lock moves to another frame when, over a window of
/// [`SWITCH_WINDOW_MESSAGES`] messages of the stream, the locked frame sent none and the
/// other frame at least half. Two sensors interleaved on one topic would otherwise be
/// fused as one (duplicate and backward stamps, mixed lever arms and mounting), and the
/// node has one IMU and one antenna; a stray publisher that sent first must not silence
/// the real sensor for good. The lock survives filter resets.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(super) struct FrameLock {
    locked: Option<String>,
    /// The frame was configured: it never moves.
    configured: bool,
    /// The current window: messages in all, of the locked frame, of other frames.
    window_total: u32,
    window_locked: u32,
    window_others: Vec<(String, u32)>,
    /// A foreign frame of the current window, else of the previous one.
    conflict: Option<String>,
    previous_conflict: Option<String>,
    /// The lock moved and no message of the new frame was admitted yet.
    switch_pending: bool,
}

impl FrameLock {
    /// A lock on the configured `frame_id`.
    pub(super) fn configured(frame_id: &str) -> Self {
        Self {
            locked: Some(frame_id.to_owned()),
            configured: true,
            ..Self::default()
        }
    }

    /// Counts a message from `frame_id` and tells what becomes of it.
    pub(super) fn admit(&mut self, frame_id: &str) -> Admission {
        if self.locked.is_some() {
            self.count(frame_id);
        }
        match self.locked.as_deref() {
            Some(locked) if locked != frame_id => {
                self.conflict = Some(frame_id.to_owned());
                Admission::Foreign
            }
            Some(_) if std::mem::take(&mut self.switch_pending) => Admission::Switched,
            _ => Admission::Admitted,
        }
    }

    /// Locks `frame_id` when no frame is locked yet (the engine accepted its message).
    pub(super) fn accepted(&mut self, frame_id: &str) {
        if self.locked.is_none() {
            self.locked = Some(frame_id.to_owned());
        }
    }

    /// The locked frame (empty while none is).
    pub(super) fn locked(&self) -> &str {
        self.locked.as_deref().unwrap_or_default()
    }

    /// A frame other than the locked one that sent in this window or the previous one.
    pub(super) fn conflict(&self) -> Option<&str> {
        self.conflict
            .as_deref()
            .or(self.previous_conflict.as_deref())
    }

    /// Counts `frame_id` in the window; at its end, moves the lock when the locked frame
    /// went silent.
    fn count(&mut self, frame_id: &str) {
        self.window_total += 1;
        if self.locked.as_deref() == Some(frame_id) {
            self.window_locked += 1;
        } else if let Some((_, n)) = self.window_others.iter_mut().find(|(f, _)| f == frame_id) {
            *n += 1;
        } else if self.window_others.len() < TRACKED_FRAMES {
            self.window_others.push((frame_id.to_owned(), 1));
        }
        if self.window_total < SWITCH_WINDOW_MESSAGES {
            return;
        }
        let leader = self
            .window_others
            .iter()
            .max_by_key(|(_, n)| *n)
            .filter(|(_, n)| 2 * n >= self.window_total);
        if let (false, 0, Some((frame, _))) = (self.configured, self.window_locked, leader) {
            self.locked = Some(frame.clone());
            self.switch_pending = true;
        }
        self.window_total = 0;
        self.window_locked = 0;
        self.window_others.clear();
        self.previous_conflict = self.conflict.take();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn send(lock: &mut FrameLock, frame_id: &str, n: u32) -> Vec<Admission> {
        (0..n)
            .map(|_| {
                let a = lock.admit(frame_id);
                if a != Admission::Foreign {
                    lock.accepted(frame_id);
                }
                a
            })
            .collect()
    }

    #[test]
    fn a_silent_locked_frame_gives_way_to_the_one_that_keeps_arriving() {
        let mut lock = FrameLock::default();
        send(&mut lock, "stray", 5);
        assert_eq!(lock.locked(), "stray");
        let admissions = send(&mut lock, "imu", 2 * SWITCH_WINDOW_MESSAGES);
        assert_eq!(lock.locked(), "imu");
        let switched = admissions.iter().position(|a| *a == Admission::Switched);
        let first_window_end = SWITCH_WINDOW_MESSAGES as usize - 4;
        assert!(
            switched.is_some_and(|k| k > first_window_end),
            "the stray frame sent in the first window: {switched:?}"
        );
        let k = switched.unwrap_or_default();
        assert!(admissions[..k].iter().all(|a| *a == Admission::Foreign));
        assert!(admissions[k + 1..]
            .iter()
            .all(|a| *a == Admission::Admitted));
        assert_eq!(lock.conflict(), Some("imu"), "reported for a window");
        send(&mut lock, "imu", 2 * SWITCH_WINDOW_MESSAGES);
        assert_eq!(lock.conflict(), None, "two clean windows");
    }

    #[test]
    fn a_live_locked_frame_keeps_the_lock() {
        let mut lock = FrameLock::default();
        send(&mut lock, "imu", 1);
        for _ in 0..10 * SWITCH_WINDOW_MESSAGES / 100 {
            send(&mut lock, "other", 99);
            assert_eq!(send(&mut lock, "imu", 1), [Admission::Admitted]);
        }
        assert_eq!(lock.locked(), "imu");
        assert_eq!(lock.conflict(), Some("other"));
    }

    #[test]
    fn a_configured_frame_never_moves() {
        let mut lock = FrameLock::configured("imu");
        assert_eq!(
            send(&mut lock, "stray", 3 * SWITCH_WINDOW_MESSAGES)[0],
            Admission::Foreign
        );
        assert_eq!(lock.locked(), "imu");
        assert_eq!(send(&mut lock, "imu", 1), [Admission::Admitted]);
        assert_eq!(lock.conflict(), Some("stray"));
    }
}
