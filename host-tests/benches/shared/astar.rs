//! One exact A* with the `pathfinding` crate (8 moves without corner cutting, integer costs
//! 1000 / 1414), shared by the `large` bench and the `full_run` example (`#[path]` modules: the
//! crate's library cannot use a dev-dependency).

use ohaca::Point;
use ohaca_host_tests::maps::Map;
use ohaca_host_tests::reference::step_allowed;
use pathfinding::prelude::astar;

/// One exact A* with the `pathfinding` crate: the path's cost in thousandths.
pub fn astar_cost(map: &Map, start: Point, goal: Point) -> Option<u32> {
    const MOVES: [(i64, i64, u32); 8] = [
        (1, 0, 1000),
        (1, 1, 1414),
        (0, 1, 1000),
        (-1, 1, 1414),
        (-1, 0, 1000),
        (-1, -1, 1414),
        (0, -1, 1000),
        (1, -1, 1414),
    ];
    let r = astar(
        &start,
        |&p| {
            MOVES
                .iter()
                .filter(move |&&(dx, dy, _)| step_allowed(map, p, dx, dy))
                .map(move |&(dx, dy, c)| {
                    (
                        Point::new((i64::from(p.x) + dx) as u16, (i64::from(p.y) + dy) as u16),
                        c,
                    )
                })
        },
        |&p| {
            let dx = u32::from(p.x.abs_diff(goal.x));
            let dy = u32::from(p.y.abs_diff(goal.y));
            1000 * dx.max(dy) + 414 * dx.min(dy)
        },
        |&p| p == goal,
    );
    r.map(|(_, c)| c)
}
