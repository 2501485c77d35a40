//! The Nav2 action server `compute_path_to_pose` (`nav2_msgs/action/ComputePathToPose`) over
//! ros2-client's synchronous [`ActionServer`]: its three services (`send_goal`, `get_result`,
//! `cancel_goal`) and its status topic, polled by the node's loop.
//!
//! Every goal is accepted, planned at once (the node's loop is single-threaded: a plan blocks
//! it for its duration) and kept with its result until the caller asks for it: `SUCCEEDED`
//! with the path and the planning time, or `ABORTED` with Nav2's `error_code` and an
//! `error_msg` (goal off the map, start blocked, device unreachable or busy, ...). A cancel
//! request finds every goal already finished (`GOAL_TERMINATED`). The last [`KEPT`] results
//! are kept; older ones are forgotten (`get_result` then answers `UNKNOWN`).

use std::collections::VecDeque;

use ros2_client::action::{
    ActionServer, CancelGoalResponse, GetResultResponse, GoalId, GoalInfo, GoalStatusEnum,
    SendGoalResponse,
};
use ros2_client::action_msgs::{CancelGoalResponseEnum, GoalStatus, GoalStatusArray};
use ros2_client::builtin_interfaces;

use super::msg::{ComputePathFeedback, ComputePathGoal, ComputePathResult};

/// Finished goals kept for `get_result`.
pub const KEPT: usize = 64;

/// The action server's type.
pub type PathServer = ActionServer<ComputePathGoal, ComputePathResult, ComputePathFeedback>;

/// A finished goal.
struct Finished {
    id: GoalId,
    stamp: builtin_interfaces::Time,
    status: GoalStatusEnum,
    result: ComputePathResult,
}

/// See the module docs.
pub struct PathAction {
    server: PathServer,
    done: VecDeque<Finished>,
}

impl PathAction {
    /// Serve `server`.
    pub fn new(server: PathServer) -> Self {
        PathAction {
            server,
            done: VecDeque::new(),
        }
    }

    fn publish_statuses(&self, running: Option<(GoalId, builtin_interfaces::Time)>) {
        let mut status_list: Vec<GoalStatus> = self
            .done
            .iter()
            .map(|f| GoalStatus {
                goal_info: GoalInfo {
                    goal_id: f.id,
                    stamp: f.stamp,
                },
                status: f.status,
            })
            .collect();
        if let Some((id, stamp)) = running {
            status_list.push(GoalStatus {
                goal_info: GoalInfo { goal_id: id, stamp },
                status: GoalStatusEnum::Executing,
            });
        }
        if let Err(e) = self
            .server
            .send_goal_statuses(GoalStatusArray { status_list })
        {
            log::warn!("action: cannot publish goal statuses: {e:?}");
        }
    }

    /// Serve what arrived: new goals (planned with `plan`: `Ok` succeeded, `Err` aborted, both
    /// with their result), result requests, cancel requests. Returns true if anything did.
    pub fn poll(
        &mut self,
        plan: &mut dyn FnMut(&ComputePathGoal) -> Result<ComputePathResult, ComputePathResult>,
    ) -> bool {
        let mut busy = false;
        loop {
            let (req_id, req) = match self.server.receive_goal() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => {
                    log::warn!("action: unreadable goal request: {e:?}");
                    busy = true;
                    continue;
                }
            };
            busy = true;
            let stamp = builtin_interfaces::Time::now();
            if let Err(e) = self.server.send_goal_response(
                req_id,
                SendGoalResponse {
                    accepted: true,
                    stamp,
                },
            ) {
                log::warn!("action: cannot answer a goal request: {e:?}");
                continue;
            }
            self.publish_statuses(Some((req.goal_id, stamp)));
            let (status, result) = match plan(&req.goal) {
                Ok(r) => (GoalStatusEnum::Succeeded, r),
                Err(r) => (GoalStatusEnum::Aborted, r),
            };
            self.done.push_back(Finished {
                id: req.goal_id,
                stamp,
                status,
                result,
            });
            while self.done.len() > KEPT {
                self.done.pop_front();
            }
            self.publish_statuses(None);
        }
        loop {
            let (req_id, req) = match self.server.receive_result_request() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => {
                    log::warn!("action: unreadable result request: {e:?}");
                    busy = true;
                    continue;
                }
            };
            busy = true;
            let answer = match self.done.iter().find(|f| f.id == req.goal_id) {
                Some(f) => GetResultResponse {
                    status: f.status,
                    result: f.result.clone(),
                },
                None => GetResultResponse {
                    status: GoalStatusEnum::Unknown,
                    result: ComputePathResult::default(),
                },
            };
            if let Err(e) = self.server.send_result(req_id, answer) {
                log::warn!("action: cannot send a result: {e:?}");
            }
        }
        loop {
            let req_id = match self.server.receive_cancel_request() {
                Ok(Some((id, _))) => id,
                Ok(None) => break,
                Err(e) => {
                    log::warn!("action: unreadable cancel request: {e:?}");
                    busy = true;
                    continue;
                }
            };
            busy = true;
            let answer = CancelGoalResponse {
                return_code: CancelGoalResponseEnum::GoalTerminated,
                goals_canceling: Vec::new(),
            };
            if let Err(e) = self.server.send_cancel_response(req_id, answer) {
                log::warn!("action: cannot answer a cancel request: {e:?}");
            }
        }
        busy
    }
}
