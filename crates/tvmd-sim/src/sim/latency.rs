//! Feedback latency in whole controller periods (`disturbances.feedback_latency`): the state
//! fed back at tick `k` is the one of tick `k - L` (the first tick's until `L` ticks have
//! passed), as an estimator and a link that lag by `L` periods would deliver it.

use std::collections::VecDeque;

use tvmd_plant::physics::PlantState;

/// The last `L + 1` fed-back states.
#[derive(Clone, Debug)]
pub struct FeedbackDelay {
    latency: usize,
    states: VecDeque<PlantState>,
}

impl FeedbackDelay {
    /// A delay of `latency` controller periods (0: none).
    pub fn new(latency: u32) -> Self {
        let latency = latency as usize;
        Self {
            latency,
            states: VecDeque::with_capacity(latency + 1),
        }
    }

    /// Takes this tick's state and returns the one the controller sees.
    pub fn delay(&mut self, state: PlantState) -> PlantState {
        self.states.push_back(state);
        while self.states.len() > self.latency + 1 {
            self.states.pop_front();
        }
        self.states.front().copied().unwrap_or(state)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn delays_by_whole_ticks_and_holds_the_first_state() {
        let at = |z: f64| PlantState::at_rest(Vector3::new(0.0, 0.0, z));
        let mut none = FeedbackDelay::new(0);
        assert_eq!(none.delay(at(1.0)).position.z, 1.0);
        assert_eq!(none.delay(at(2.0)).position.z, 2.0);
        let mut two = FeedbackDelay::new(2);
        let seen: Vec<f64> = (0..5).map(|k| two.delay(at(k as f64)).position.z).collect();
        assert_eq!(seen, [0.0, 0.0, 0.0, 1.0, 2.0]);
    }
}
