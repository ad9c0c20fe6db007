//! One-off work outside the steps (reading a large file) split over
//! scoped threads of its own: the step's team runs only the steps.

/// Where the parts of a piece of one-off work run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Run {
    /// On threads of their own, but the first ([`each`]).
    Threads,
    /// One after another on this thread: the same parts and the same
    /// result without the threads (for the fuzzer, which reads every input
    /// in pieces).
    #[cfg_attr(not(any(test, fuzzing)), allow(dead_code))]
    Here,
}

impl Run {
    /// `part(k)` for every `k < count`, in order; `None` if any is `None`
    /// (or, on threads, a thread could not be started).
    pub(crate) fn each<T: Send>(
        self,
        count: usize,
        part: impl Fn(usize) -> Option<T> + Sync,
    ) -> Option<Vec<T>> {
        match self {
            Run::Threads => each(count, part),
            Run::Here => (0..count).map(part).collect(),
        }
    }
}

/// `each(k)` for every `k < count`: `k = 0` on this thread, the others on
/// threads of their own. `None` if any gives `None` or a thread could not
/// be started (the caller then does the work another way).
pub(crate) fn each<T: Send>(
    count: usize,
    each: impl Fn(usize) -> Option<T> + Sync,
) -> Option<Vec<T>> {
    std::thread::scope(|scope| {
        let each = &each;
        let others: Vec<_> = (1..count)
            .map(|k| std::thread::Builder::new().spawn_scoped(scope, move || each(k)))
            .collect();
        let first = (count > 0).then(|| each(0));
        let others = others.into_iter().map(|o| o.ok()?.join().ok()?);
        first.into_iter().chain(others).collect()
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_part_in_order_or_none() {
        assert_eq!(super::each(5, |k| Some(k * k)), Some(vec![0, 1, 4, 9, 16]));
        assert_eq!(super::each(0, Some), Some(vec![]));
        assert_eq!(super::each(3, |k| (k != 2).then_some(k)), None);
        for run in [super::Run::Threads, super::Run::Here] {
            assert_eq!(run.each(4, |k| Some(k + 1)), Some(vec![1, 2, 3, 4]));
            assert_eq!(run.each(4, |k| (k != 0).then_some(k)), None);
        }
    }
}
