//! The bounded queue between the simulation thread and the recording's writer thread.
//!
//! `std::sync::mpsc` wakes the receiving thread at every send. A frame every few hundred
//! microseconds then costs the simulation thread a wake-up of an idle writer thread each time:
//! on a virtual machine, where waking an idle CPU goes through the hypervisor, about 20 µs per
//! frame, several times the whole frame's gathering (`magsep bench recording`, the levitation
//! scene: 24.6 µs per frame). Here a send wakes the writer only when the queue is three
//! quarters full or the item is urgent (someone waits for it: the file's end, a call with a
//! reply); otherwise the writer finds the items when it next looks by itself. It looks every
//! [`POLL_MIN`] while items keep coming and backs off to [`POLL_MAX`] while none do, so a run
//! that records often seldom wakes it and an idle writer costs a few wake-ups a second. Hand-written because no maintained channel crate offers a send that
//! does not notify; it is a mutex, two condition variables and a `VecDeque`.
//!
//! Memory stays bounded: each item is sent with its weight (its size in bytes, roughly), and a
//! sender waits while `capacity` items or `budget` bytes are queued (an item heavier than the
//! whole budget still goes, alone). The slack matters: a writer thread that is not running
//! (just started, writing a chunk, or waiting for a CPU on a loaded machine) must not stall the
//! simulation, and on a loaded 2-core machine a runnable thread can wait tens of milliseconds
//! for a CPU: with a queue of 16 calls, the levitation scene's 0.4 ms frames filled it (the
//! 13th frame waited for the writer thread's first turn, 1-100 ms). Items are received
//! in the order they were sent. Dropping the sender closes the queue (the receiver gets what
//! is left, then `None`); dropping the receiver makes later sends fail with the item.

use std::collections::VecDeque;
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use std::time::Duration;

/// Shortest wait of the receiver between looks at the queue.
pub const POLL_MIN: Duration = Duration::from_micros(500);
/// Longest wait of the receiver between looks at the queue: an item sent without a wake-up
/// waits at most this long.
pub const POLL_MAX: Duration = Duration::from_millis(20);

struct State<T> {
    /// The items, each with its weight.
    items: VecDeque<(T, usize)>,
    /// The sum of the queued items' weights.
    weight: usize,
    /// The sender is gone (no more items will come).
    sender_gone: bool,
    /// The receiver is gone (sends fail).
    receiver_gone: bool,
    /// The receiver is waiting for items.
    receiver_waiting: bool,
    /// The sender is waiting for room.
    sender_waiting: bool,
}

struct Shared<T> {
    state: Mutex<State<T>>,
    /// Signalled for the receiver: items (or the sender's end) are there.
    ready: Condvar,
    /// Signalled for the sender: room (or the receiver's end) is there.
    room: Condvar,
    capacity: usize,
    budget: usize,
}

impl<T> State<T> {
    /// Whether an item of `weight` must wait for room.
    fn full_for(&self, weight: usize, capacity: usize, budget: usize) -> bool {
        !self.items.is_empty()
            && (self.items.len() >= capacity || self.weight.saturating_add(weight) > budget)
    }
}

impl<T> Shared<T> {
    fn lock(&self) -> MutexGuard<'_, State<T>> {
        // a panic while holding the lock leaves plain data: go on with it
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }
}

/// The sending side (the simulation thread's).
pub struct Sender<T>(Arc<Shared<T>>);

/// The receiving side (the writer thread's), with its current wait between looks at the
/// queue.
pub struct Receiver<T>(Arc<Shared<T>>, std::cell::Cell<Duration>);

/// A queue holding at most `capacity` (at least 1) items and `budget` bytes of weight.
pub fn mailbox<T>(capacity: usize, budget: usize) -> (Sender<T>, Receiver<T>) {
    let shared = Arc::new(Shared {
        state: Mutex::new(State {
            items: VecDeque::new(),
            weight: 0,
            sender_gone: false,
            receiver_gone: false,
            receiver_waiting: false,
            sender_waiting: false,
        }),
        ready: Condvar::new(),
        room: Condvar::new(),
        capacity: capacity.max(1),
        budget,
    });
    (
        Sender(shared.clone()),
        Receiver(shared, std::cell::Cell::new(POLL_MIN)),
    )
}

impl<T> Sender<T> {
    /// Queue `item` of `weight` bytes, waiting while the queue is full; `urgent`: wake the
    /// receiver now (else it is woken only once the queue is three quarters full, by count or
    /// weight). `Err(item)` when the receiver is gone.
    pub fn send(&self, item: T, weight: usize, urgent: bool) -> Result<(), T> {
        let s = &*self.0;
        let mut st = s.lock();
        while st.full_for(weight, s.capacity, s.budget) && !st.receiver_gone {
            if st.receiver_waiting {
                s.ready.notify_one();
            }
            st.sender_waiting = true;
            st = s.room.wait(st).unwrap_or_else(|p| p.into_inner());
            st.sender_waiting = false;
        }
        if st.receiver_gone {
            return Err(item);
        }
        st.items.push_back((item, weight));
        st.weight = st.weight.saturating_add(weight);
        let filling = 4 * st.items.len() >= 3 * s.capacity
            || st.weight.saturating_mul(4) >= s.budget.saturating_mul(3);
        if st.receiver_waiting && (urgent || filling) {
            s.ready.notify_one();
        }
        Ok(())
    }
}

impl<T> Drop for Sender<T> {
    fn drop(&mut self) {
        let mut st = self.0.lock();
        st.sender_gone = true;
        if st.receiver_waiting {
            self.0.ready.notify_one();
        }
    }
}

impl<T> Receiver<T> {
    /// The next item, waiting for one; `None` once the sender is gone and the queue is empty.
    pub fn recv(&self) -> Option<T> {
        let s = &*self.0;
        let mut st = s.lock();
        loop {
            if let Some((item, weight)) = st.items.pop_front() {
                st.weight -= weight;
                if st.sender_waiting {
                    s.room.notify_one();
                }
                return Some(item);
            }
            if st.sender_gone {
                return None;
            }
            st.receiver_waiting = true;
            st = match s.ready.wait_timeout(st, self.1.get()) {
                Ok((g, _)) => g,
                Err(p) => p.into_inner().0,
            };
            st.receiver_waiting = false;
            // look more often while items keep coming, less often while none do
            let poll = if st.items.is_empty() {
                (self.1.get() * 2).min(POLL_MAX)
            } else {
                (self.1.get() / 2).max(POLL_MIN)
            };
            self.1.set(poll);
        }
    }
}

impl<T> Drop for Receiver<T> {
    fn drop(&mut self) {
        let mut st = self.0.lock();
        st.receiver_gone = true;
        st.items.clear();
        if st.sender_waiting {
            self.0.room.notify_one();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn items_arrive_in_order_through_a_small_queue() {
        let (tx, rx) = mailbox::<u32>(3, usize::MAX);
        let reader = std::thread::spawn(move || {
            let mut got = Vec::new();
            while let Some(x) = rx.recv() {
                got.push(x);
            }
            got
        });
        for k in 0..1000 {
            // mostly lazy sends: the queue fills and the sender must wake the reader
            tx.send(k, 1, k % 97 == 0).unwrap();
        }
        drop(tx);
        assert_eq!(reader.join().unwrap(), (0..1000).collect::<Vec<_>>());
    }

    #[test]
    fn a_lazy_item_arrives_by_the_receiver_s_own_poll() {
        let (tx, rx) = mailbox::<u32>(16, usize::MAX);
        let (seen, got) = std::sync::mpsc::channel();
        let reader = std::thread::spawn(move || {
            while let Some(x) = rx.recv() {
                let _ = seen.send(x);
            }
        });
        // the reader is asleep by now; a lazy send does not wake it, its poll finds the item
        std::thread::sleep(Duration::from_millis(30));
        tx.send(1, 1, false).unwrap();
        assert_eq!(got.recv_timeout(Duration::from_secs(5)), Ok(1));
        tx.send(2, 1, true).unwrap();
        assert_eq!(got.recv_timeout(Duration::from_secs(5)), Ok(2));
        drop(tx);
        reader.join().unwrap();
    }

    #[test]
    fn a_send_after_the_receiver_is_gone_gives_the_item_back() {
        let (tx, rx) = mailbox::<String>(2, usize::MAX);
        tx.send("a".into(), 1, false).unwrap();
        drop(rx);
        assert_eq!(tx.send("b".into(), 1, true), Err("b".to_string()));
    }

    #[test]
    fn a_full_queue_blocks_until_the_receiver_takes_or_goes() {
        let (tx, rx) = mailbox::<u32>(1, usize::MAX);
        tx.send(1, 1, false).unwrap();
        let sender = std::thread::spawn(move || tx.send(2, 1, false));
        std::thread::sleep(Duration::from_millis(20));
        assert_eq!(rx.recv(), Some(1));
        assert_eq!(sender.join().unwrap(), Ok(()));
        assert_eq!(rx.recv(), Some(2));
        // the sender is gone now: the queue is closed
        assert_eq!(rx.recv(), None);
    }

    #[test]
    fn the_byte_budget_bounds_the_queue_and_a_heavy_item_still_goes_alone() {
        let (tx, rx) = mailbox::<u32>(100, 10);
        tx.send(1, 6, false).unwrap();
        // 6 + 6 > 10: the second waits although only one item of 100 is queued
        let sender = std::thread::spawn(move || {
            tx.send(2, 6, false).unwrap();
            // heavier than the whole budget: goes once the queue is empty
            tx.send(3, 50, false).unwrap();
            tx
        });
        std::thread::sleep(Duration::from_millis(20));
        assert!(!sender.is_finished(), "the second item must wait for room");
        assert_eq!(rx.recv(), Some(1));
        assert_eq!(rx.recv(), Some(2));
        assert_eq!(rx.recv(), Some(3));
        let tx = sender.join().unwrap();
        drop(tx);
        assert_eq!(rx.recv(), None);
    }
}
