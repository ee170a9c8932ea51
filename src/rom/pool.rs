//! Work spaces handed out to whichever thread runs next: a reduced model keeps its Newton
//! work space (factorization, element caches) in itself, so each concurrent run needs its
//! own, while the object that owns them ([`super::Rom`], an estimator) is shared by
//! reference across threads (a sweep's rayon workers, a Python caller's threads).
//!
//! A work space holds nothing of a run's parameters between runs (the `ParametricModel`
//! contract, tests/parameters.rs), so which one a run gets does not change its result.

use crate::error::Result;
use std::sync::Mutex;

type Make<'a, T> = Box<dyn Fn() -> Result<T> + Send + Sync + 'a>;

/// Work spaces built on demand by `make` and kept for reuse; at most as many exist as runs
/// ever ran at once. `'a`: what `make` borrows (`'static` for an owning object such as
/// [`super::Rom`]; a sweep's full models borrow the model for the sweep's length).
pub struct Pool<'a, T> {
    free: Mutex<Vec<T>>,
    make: Make<'a, T>,
}

impl<'a, T: Send> Pool<'a, T> {
    pub fn new(make: impl Fn() -> Result<T> + Send + Sync + 'a) -> Self {
        Pool { free: Mutex::new(Vec::new()), make: Box::new(make) }
    }

    /// Keeps `w` for the next run (one built ahead to surface a failure early).
    pub fn put(&self, w: T) {
        self.free.lock().unwrap_or_else(|e| e.into_inner()).push(w);
    }

    /// Runs `f` with a free work space (a new one when none is free) and keeps it afterwards.
    pub fn with<R>(&self, f: impl FnOnce(&mut T) -> R) -> Result<R> {
        let taken = self.free.lock().unwrap_or_else(|e| e.into_inner()).pop();
        let mut w = match taken {
            Some(w) => w,
            None => (self.make)()?,
        };
        let r = f(&mut w);
        self.put(w);
        Ok(r)
    }
}

#[cfg(test)]
mod tests {
    use super::Pool;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::Arc;

    /// Sequential use builds one work space and reuses it; a failing `make` is the caller's
    /// error, not a panic.
    #[test]
    fn one_work_space_serves_sequential_runs() {
        let made = Arc::new(AtomicUsize::new(0));
        let m = Arc::clone(&made);
        let pool = Pool::new(move || Ok(m.fetch_add(1, Ordering::SeqCst)));
        for _ in 0..5 {
            assert_eq!(pool.with(|w| *w).unwrap(), 0);
        }
        assert_eq!(made.load(Ordering::SeqCst), 1);
        let bad: Pool<'_, u8> = Pool::new(|| Err(crate::Error::usage("no")));
        assert!(bad.with(|_| ()).is_err());
    }

    /// Two runs at once get two work spaces.
    #[test]
    fn concurrent_runs_get_their_own() {
        let made = Arc::new(AtomicUsize::new(0));
        let m = Arc::clone(&made);
        let pool = Pool::new(move || Ok(m.fetch_add(1, Ordering::SeqCst)));
        let outer = pool.with(|a| pool.with(|b| (*a, *b)).unwrap()).unwrap();
        assert_eq!(outer, (0, 1));
        assert_eq!(made.load(Ordering::SeqCst), 2);
    }
}
