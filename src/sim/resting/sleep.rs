//! Sleep: islands of touching resting balls that have stayed still fall asleep together, and
//! wake together. Steps of [`rest_and_sleep`](super::rest_and_sleep) on its state.

use bevy::math::DVec2;

use super::contacts::NearPair;
use super::islands::Islands;
use super::state::RestingState;
use crate::sim::ball::{Rest, RestState};

/// A resting ball slower than this, pixels per second, counts as still towards sleep.
pub const SLEEP_SPEED: f64 = 2.0;
/// Seconds every ball of an island must stay still before the island sleeps.
pub const TIME_TO_SLEEP: f64 = 0.5;

/// Step 1: wakes the islands asked for (or all), and those a hit set one ball of flying; a
/// resting ball a hit set flying flies.
pub fn wake(state: &mut RestingState, held: &[bool]) {
    let mut islands = std::mem::take(&mut state.wake_requests);
    for (rest, &held) in state.rests.iter_mut().zip(held) {
        match rest.state {
            RestState::Asleep { island } if !held || state.wake_all => islands.push(island),
            RestState::Resting if !held => *rest = Rest::default(),
            _ => {}
        }
    }
    state.wake_all = false;
    wake_islands(state, islands);
}

/// Step 2's second half: an awake ball touching a sleeping one wakes its island.
pub fn wake_touched(state: &mut RestingState) {
    let islands: Vec<u32> = state
        .near
        .pairs
        .iter()
        .filter(|pair| pair.touching)
        .filter_map(|&NearPair { a, b, .. }| {
            match (state.rests[a as usize].state, state.rests[b as usize].state) {
                (RestState::Asleep { island }, other) | (other, RestState::Asleep { island })
                    if !matches!(other, RestState::Asleep { .. }) =>
                {
                    Some(island)
                }
                _ => None,
            }
        })
        .collect();
    wake_islands(state, islands);
}

fn wake_islands(state: &mut RestingState, mut islands: Vec<u32>) {
    if islands.is_empty() {
        return;
    }
    islands.sort_unstable();
    islands.dedup();
    for island in &islands {
        state.island_load.remove(island);
    }
    for rest in &mut state.rests {
        if let RestState::Asleep { island } = rest.state
            && islands.binary_search(&island).is_ok()
        {
            *rest = Rest::default();
        }
    }
}

/// Step 5: islands of touching resting balls, every one still for [`TIME_TO_SLEEP`] and none
/// touching a flying ball, fall asleep: velocity exactly zero, their weight on the walls
/// remembered so the pressure keeps counting it.
pub fn fall_asleep(state: &mut RestingState, velocities: &mut [DVec2], dt: f64) {
    let count = state.rests.len();
    let mut islands = Islands::new(count);
    let mut blocked = vec![false; count];
    let resting = |rest: &Rest| rest.state == RestState::Resting;
    for &NearPair { a, b, .. } in state.near.pairs.iter().filter(|pair| pair.touching) {
        let (ra, rb) = (&state.rests[a as usize], &state.rests[b as usize]);
        match (resting(ra), resting(rb)) {
            (true, true) => islands.join(a, b),
            (true, false) if !rb.is_asleep() => blocked[a as usize] = true,
            (false, true) if !ra.is_asleep() => blocked[b as usize] = true,
            _ => {}
        }
    }
    // An island sleeps only if every member may: any member that may not blocks its root.
    let mut may_sleep = vec![true; count];
    for index in 0..count {
        let rest = &state.rests[index];
        if resting(rest) && (blocked[index] || rest.still_for < TIME_TO_SLEEP) {
            may_sleep[islands.root(index as u32) as usize] = false;
        }
    }
    let mut island_of_root: Vec<Option<u32>> = vec![None; count];
    for (index, velocity) in velocities.iter_mut().enumerate() {
        if !resting(&state.rests[index]) {
            continue;
        }
        let root = islands.root(index as u32) as usize;
        if !may_sleep[root] {
            continue;
        }
        let island = *island_of_root[root].get_or_insert_with(|| {
            state.next_island = state.next_island.wrapping_add(1);
            state.next_island
        });
        state.rests[index].state = RestState::Asleep { island };
        *velocity = DVec2::ZERO;
        let load = state
            .near
            .wall_impulse_of
            .get(index)
            .copied()
            .unwrap_or(0.0)
            / dt;
        *state.island_load.entry(island).or_insert(0.0) += load;
    }
}
