//! What a simplification cost on the device's side, counted as the preparation and the rounds
//! go: the report's `device_waits`, `submits`, `dispatches`, `bind_groups_created`,
//! `bytes_uploaded`, `bytes_read_back` and the host's share of the call.

use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

/// What a simplification cost on the device's side, counted as it goes (the report's
/// `device_waits`, `submits`, ...).
#[derive(Default)]
pub struct Costs {
    pub waits: AtomicU64,
    pub submits: AtomicU64,
    pub dispatches: AtomicU64,
    pub bind_groups: AtomicU64,
    pub uploaded: AtomicU64,
    pub read_back: AtomicU64,
    /// Nanoseconds the host spent blocked on the device.
    pub blocked_ns: AtomicU64,
}

impl Costs {
    pub(crate) fn add(counter: &AtomicU64, n: u64) {
        counter.fetch_add(n, Relaxed);
    }

    pub fn get(counter: &AtomicU64) -> u64 {
        counter.load(Relaxed)
    }

    /// The counts into `r`, with the host's share of `call_seconds`.
    pub fn report(&self, r: &mut crate::rounds::RoundsReport, call_seconds: f64) {
        r.device_waits = Costs::get(&self.waits);
        r.submits = Costs::get(&self.submits);
        r.dispatches = Costs::get(&self.dispatches);
        r.bind_groups_created = Costs::get(&self.bind_groups);
        r.bytes_uploaded = Costs::get(&self.uploaded);
        r.bytes_read_back = Costs::get(&self.read_back);
        r.host_seconds = (call_seconds - Costs::get(&self.blocked_ns) as f64 * 1e-9).max(0.0);
    }
}
