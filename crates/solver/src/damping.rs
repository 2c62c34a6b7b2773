//! The Levenberg–Marquardt damping schedule shared by the solver's refinements (the
//! six parameters, several lasers, the lateral slide): the damping λ added to the
//! unit-diagonal normal matrix, ten times smaller after a step that lowered the cost,
//! ten times larger after one that could not be solved or did not.

/// Relative decrease of the cost below which a refinement has converged.
const RELATIVE_TOLERANCE: f64 = 1e-12;

/// λ of a refinement's first step.
const START: f64 = 1e-6;

/// Smallest λ.
const MIN: f64 = 1e-12;

/// λ beyond which no step can help: the refinement stops.
const MAX: f64 = 1e12;

/// The damping of one refinement.
pub(crate) struct Damping {
    lambda: f64,
}

impl Damping {
    /// The damping of a refinement's first step.
    pub(crate) fn new() -> Self {
        Self { lambda: START }
    }

    /// λ, to add to the diagonal of the unit-diagonal normal matrix.
    pub(crate) fn lambda(&self) -> f64 {
        self.lambda
    }

    /// Whether a step whose quadratic model predicts `predicted` decrease of `cost` is
    /// too small to try: converged.
    pub(crate) fn negligible(predicted: f64, cost: f64) -> bool {
        predicted <= RELATIVE_TOLERANCE * cost
    }

    /// After a step that lowered the cost by `decrease` to `cost`: less damping;
    /// whether the refinement has converged.
    pub(crate) fn accepted(&mut self, decrease: f64, cost: f64) -> bool {
        self.lambda = (self.lambda * 0.1).max(MIN);
        decrease <= RELATIVE_TOLERANCE * cost
    }

    /// After a step that could not be solved or did not lower the cost: more damping;
    /// whether λ has grown beyond use (stop).
    pub(crate) fn rejected(&mut self) -> bool {
        self.lambda *= 10.0;
        self.lambda > MAX
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn damping_falls_after_success_and_rises_to_a_stop_after_failures() {
        let mut d = Damping::new();
        assert!(!d.accepted(1.0, 1.0));
        assert_eq!(d.lambda(), 1e-7);
        for _ in 0..10 {
            d.accepted(1.0, 1.0);
        }
        assert_eq!(d.lambda(), MIN);
        assert!(d.accepted(1e-13, 1.0));
        let failures = (0..100).take_while(|_| !d.rejected()).count();
        assert!(
            (23..=25).contains(&failures),
            "{failures}: 1e-12 to 1e12 by tens"
        );
        assert!(d.lambda() > MAX);
        assert!(Damping::negligible(0.0, 1.0));
        assert!(!Damping::negligible(1e-6, 1.0));
    }
}
