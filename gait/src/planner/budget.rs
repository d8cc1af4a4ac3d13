//! How long a plan may take to find, and what finding it cost.
//!
//! The library reads no clock: its caller hands the search a [`Budget`],
//! which the search polls before every expansion. The budget counts
//! expansions itself (deterministic: the same request gives the same plan
//! under the same count) and asks an optional [`Stop`] — the caller's
//! clock and cancel flag — whether to go on. The daemon gives it its wall
//! clock and its cancel flag; a lockstep run gives it neither, so its plans
//! depend on the request alone.

/// Why the search was told to stop before it proved anything.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Halt {
    /// The time or expansion budget ran out.
    OutOfBudget,
    /// The caller canceled the request (a cancel, or a newer goal).
    Canceled,
}

/// The caller's side of a budget: polled before each expansion, it says
/// whether the search must stop now. Implementations must be cheap (a
/// clock read and an atomic load at most).
pub trait Stop {
    /// `Some` to stop the search now.
    fn poll(&mut self) -> Option<Halt>;
}

/// Never stops on its own (the expansion count still bounds the search).
#[derive(Debug, Clone, Copy, Default)]
pub struct Unbounded;

impl Stop for Unbounded {
    fn poll(&mut self) -> Option<Halt> {
        None
    }
}

/// The limits of one planning request.
pub struct Budget<'a> {
    /// Most node expansions, over every pass of the portfolio.
    pub max_expansions: u32,
    /// The caller's clock and cancel flag, if any.
    pub stop: &'a mut dyn Stop,
    used: u32,
    halted: Option<Halt>,
}

impl std::fmt::Debug for Budget<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Budget")
            .field("max_expansions", &self.max_expansions)
            .field("used", &self.used)
            .field("halted", &self.halted)
            .finish()
    }
}

impl<'a> Budget<'a> {
    /// A budget of `max_expansions`, stopped early by `stop`.
    pub fn new(max_expansions: u32, stop: &'a mut dyn Stop) -> Self {
        Self {
            max_expansions,
            stop,
            used: 0,
            halted: None,
        }
    }

    /// Takes one expansion from the budget; `Err` once it is spent or the
    /// caller says stop (sticky: every later call fails the same way).
    pub fn take(&mut self) -> Result<(), Halt> {
        if let Some(h) = self.halted {
            return Err(h);
        }
        let h = if self.used >= self.max_expansions {
            Some(Halt::OutOfBudget)
        } else {
            self.stop.poll()
        };
        if let Some(h) = h {
            self.halted = Some(h);
            return Err(h);
        }
        self.used += 1;
        Ok(())
    }

    /// Whether the search was stopped, and why.
    pub fn halted(&self) -> Option<Halt> {
        self.halted
    }

    /// Expansions used so far.
    pub fn used(&self) -> u32 {
        self.used
    }
}

/// What planning one request cost (reported with every plan).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Effort {
    /// Nodes expanded, over every pass.
    pub expansions: u32,
    /// Children generated.
    pub generated: u32,
    /// Deferred actions evaluated when they came up (rolls apart, turns
    /// checked against the load at every sample).
    pub evaluated: u32,
    /// Plans built from the search's actions and checked sample by sample.
    pub built: u32,
    /// Of those, plans the exact check refused (the search then goes on).
    pub refused: u32,
    /// Portfolio passes run (see [`super::alternatives::PASSES`]).
    pub passes: u32,
}

#[cfg(test)]
mod tests {
    use super::*;

    struct After(u32);
    impl Stop for After {
        fn poll(&mut self) -> Option<Halt> {
            if self.0 == 0 {
                return Some(Halt::Canceled);
            }
            self.0 -= 1;
            None
        }
    }

    #[test]
    fn the_count_and_the_callers_stop_both_end_a_budget() {
        let mut never = Unbounded;
        let mut b = Budget::new(3, &mut never);
        assert!((0..3).all(|_| b.take().is_ok()));
        assert_eq!(b.take(), Err(Halt::OutOfBudget));
        assert_eq!(b.used(), 3);
        let mut stop = After(2);
        let mut b = Budget::new(100, &mut stop);
        assert!(b.take().is_ok() && b.take().is_ok());
        assert_eq!(b.take(), Err(Halt::Canceled));
        // Sticky, even if the caller would now say go on.
        assert_eq!(b.take(), Err(Halt::Canceled));
        assert_eq!(b.halted(), Some(Halt::Canceled));
    }
}
