//! [`Outbox`]: what waits to go out to one viewer of `eotn serve`, bounded (pure: messages in
//! and out, no I/O).
//!
//! Message data (frames and their JSON) is held up to [`QueueBound`]: about 32 messages or
//! 16 MiB. A viewer that reads slower than the robot sends loses its oldest data messages, each
//! counted (and each image counted as a frame dropped); other viewers have outboxes of their
//! own. Control messages (`serverInfo`, `advertise`, status) are never dropped: a viewer that
//! lets [`MAX_CONTROL`] of them pile up is disconnected instead, as the `foxglove` server does.

use std::collections::VecDeque;

/// How much message data one viewer's outbox holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct QueueBound {
    /// Data messages, at most.
    pub messages: usize,
    /// Bytes of all queued messages, at most (one message larger than this still goes, alone).
    pub bytes: usize,
}

impl Default for QueueBound {
    fn default() -> Self {
        Self {
            messages: 32,
            bytes: 16 << 20,
        }
    }
}

/// Control messages a viewer may leave unread before it is disconnected.
pub const MAX_CONTROL: usize = 1024;

/// What a message going out is, for the outbox's bounds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Protocol control (text, or a binary message other than message data): never dropped.
    Control,
    /// Message data; `image` when its subscription is to a camera image channel.
    Data {
        /// A frame's image.
        image: bool,
    },
}

/// What the outbox let go of for a slow viewer.
#[derive(Debug, Default, Clone, Copy, PartialEq, Eq)]
pub struct Dropped {
    /// Data messages dropped (frames and their JSON).
    pub messages: u64,
    /// Of those, camera images: frames.
    pub frames: u64,
}

/// The viewer let too many control messages pile up: it must be disconnected.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("{0} control messages unread: the viewer is not reading")]
pub struct ControlOverflow(pub usize);

/// One viewer's queue of messages `M` (each with its [`Kind`] and size) waiting to be sent.
#[derive(Debug)]
pub struct Outbox<M> {
    bound: QueueBound,
    queue: VecDeque<(M, Kind, usize)>,
    data: usize,
    control: usize,
    bytes: usize,
    dropped: Dropped,
}

impl<M> Outbox<M> {
    /// An empty outbox.
    #[must_use]
    pub fn new(bound: QueueBound) -> Self {
        Self {
            bound,
            queue: VecDeque::new(),
            data: 0,
            control: 0,
            bytes: 0,
            dropped: Dropped::default(),
        }
    }

    /// Messages waiting.
    #[must_use]
    pub fn len(&self) -> usize {
        self.queue.len()
    }

    /// True when nothing waits.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.queue.is_empty()
    }

    /// Bytes waiting.
    #[must_use]
    pub fn bytes(&self) -> usize {
        self.bytes
    }

    /// Data messages waiting.
    #[must_use]
    pub fn data(&self) -> usize {
        self.data
    }

    /// What was dropped so far.
    #[must_use]
    pub const fn dropped(&self) -> Dropped {
        self.dropped
    }

    /// Queues `message` of `len` bytes; for data, the oldest data messages make room.
    ///
    /// # Errors
    /// [`ControlOverflow`] when control messages pile up past [`MAX_CONTROL`].
    pub fn push(&mut self, message: M, kind: Kind, len: usize) -> Result<(), ControlOverflow> {
        match kind {
            Kind::Control => {
                if self.control >= MAX_CONTROL {
                    return Err(ControlOverflow(self.control));
                }
                self.control += 1;
            }
            Kind::Data { .. } => {
                while self.data > 0
                    && (self.data >= self.bound.messages || self.bytes + len > self.bound.bytes)
                {
                    self.drop_oldest_data();
                }
                self.data += 1;
            }
        }
        self.bytes += len;
        self.queue.push_back((message, kind, len));
        Ok(())
    }

    /// The next message to send.
    pub fn pop(&mut self) -> Option<M> {
        let (message, kind, len) = self.queue.pop_front()?;
        self.forget(kind, len);
        Some(message)
    }

    fn forget(&mut self, kind: Kind, len: usize) {
        self.bytes -= len;
        match kind {
            Kind::Control => self.control -= 1,
            Kind::Data { .. } => self.data -= 1,
        }
    }

    fn drop_oldest_data(&mut self) {
        let Some(at) = self
            .queue
            .iter()
            .position(|(_, k, _)| matches!(k, Kind::Data { .. }))
        else {
            return;
        };
        if let Some((_, kind, len)) = self.queue.remove(at) {
            self.forget(kind, len);
            self.dropped.messages += 1;
            if kind == (Kind::Data { image: true }) {
                self.dropped.frames += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const IMAGE: Kind = Kind::Data { image: true };
    const JSON: Kind = Kind::Data { image: false };

    #[test]
    fn a_full_outbox_drops_its_oldest_data_and_counts_frames_and_messages() {
        let mut out = Outbox::new(QueueBound {
            messages: 4,
            bytes: 1 << 20,
        });
        out.push("info", Kind::Control, 10).unwrap();
        for i in 0..10 {
            out.push(
                if i % 2 == 0 { "image" } else { "json" },
                if i % 2 == 0 { IMAGE } else { JSON },
                100,
            )
            .unwrap();
        }
        // Control stays, the newest four data messages stay.
        assert_eq!(out.len(), 5);
        assert_eq!(
            out.dropped(),
            Dropped {
                messages: 6,
                frames: 3
            }
        );
        assert_eq!(out.pop(), Some("info"));
        assert_eq!(out.bytes(), 400);
        let rest: Vec<_> = std::iter::from_fn(|| out.pop()).collect();
        assert_eq!(rest, ["image", "json", "image", "json"]);
        assert_eq!(out.bytes(), 0);
    }

    #[test]
    fn the_byte_bound_holds_and_one_large_message_still_goes() {
        let mut out = Outbox::new(QueueBound {
            messages: 32,
            bytes: 1000,
        });
        for _ in 0..5 {
            out.push((), IMAGE, 300).unwrap();
        }
        assert_eq!((out.len(), out.bytes()), (3, 900));
        out.push((), IMAGE, 5000).unwrap();
        assert_eq!((out.len(), out.bytes()), (1, 5000));
        assert_eq!(out.dropped().frames, 5);
    }

    #[test]
    fn control_messages_are_never_dropped_but_too_many_overflow() {
        let mut out = Outbox::new(QueueBound::default());
        for _ in 0..MAX_CONTROL {
            out.push((), Kind::Control, 1).unwrap();
        }
        for _ in 0..100 {
            out.push((), JSON, 1).unwrap();
        }
        assert_eq!(out.len(), MAX_CONTROL + 32);
        assert_eq!(
            out.push((), Kind::Control, 1),
            Err(ControlOverflow(MAX_CONTROL))
        );
        out.pop();
        assert!(out.push((), Kind::Control, 1).is_ok());
    }
}
