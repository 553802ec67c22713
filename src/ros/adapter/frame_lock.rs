//! The `header.frame_id` an input stream is locked to.

/// The `header.frame_id` a stream is locked to.
///
/// Choice: the first message the engine accepts fixes the frame of its stream; messages
/// from any other frame are counted and dropped. Two sensors interleaved on one topic would
/// otherwise be fused as one (duplicate and backward stamps, mixed lever arms and
/// mounting), and the node has one IMU and one antenna. The lock survives filter resets.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub(super) struct FrameLock(Option<String>);

impl FrameLock {
    /// True when no frame is locked yet or `frame_id` is the locked one.
    pub(super) fn admits(&self, frame_id: &str) -> bool {
        self.0.as_deref().is_none_or(|locked| locked == frame_id)
    }

    /// Locks `frame_id` when no frame is locked yet.
    pub(super) fn accepted(&mut self, frame_id: &str) {
        if self.0.is_none() {
            self.0 = Some(frame_id.to_owned());
        }
    }

    /// The locked frame (empty while none is).
    pub(super) fn locked(&self) -> &str {
        self.0.as_deref().unwrap_or_default()
    }
}
