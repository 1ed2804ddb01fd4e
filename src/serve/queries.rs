//! The questions `tactex serve` has been asked: each one's event log (progress, then the
//! answer or the failure) as a watch channel that any number of event streams replay from
//! the start, and its press images once it is done. Only the latest few are kept.

use serde::Serialize;
use std::collections::VecDeque;
use std::sync::{Arc, Mutex};
use tactex_core::hardness::estimate::PressSequence;
use tactex_core::pipeline::{Answer, Progress};
use tokio::sync::watch;

/// Finished questions kept for their event replay and tactile images.
const KEPT: usize = 32;

/// One server-sent event: its name and JSON data.
#[derive(Clone, Debug)]
pub(super) struct LoggedEvent {
    pub name: &'static str,
    pub data: String,
}

#[derive(Default)]
pub(super) struct QueryLog {
    pub events: Vec<LoggedEvent>,
    pub done: bool,
    /// Each answered object's press, in the answer's object order.
    pub presses: Vec<Option<PressSequence>>,
}

pub(super) struct QueryRun {
    pub id: u64,
    pub log: watch::Sender<QueryLog>,
}

/// Where each touched object's tactile frames are, for the page.
#[derive(Serialize)]
struct TactileIndex {
    /// Frame 0 is the no-contact reference, frames 1.. the press from first contact on.
    frames: usize,
    travel_mm: Vec<f64>,
}

#[derive(Serialize)]
struct AnswerEvent<'a> {
    id: u64,
    answer: &'a Answer,
    tactile: Vec<Option<TactileIndex>>,
}

impl QueryRun {
    fn push(&self, name: &'static str, data: String) {
        self.log
            .send_modify(|log| log.events.push(LoggedEvent { name, data }));
    }

    pub(super) fn progress(&self, progress: &Progress) {
        let data = serde_json::to_string(progress).unwrap_or_else(|e| format!("\"{e}\""));
        self.push("progress", data);
    }

    pub(super) fn answered(&self, mut answer: Answer) {
        let presses = std::mem::take(&mut answer.presses);
        let tactile = presses
            .iter()
            .map(|p| {
                p.as_ref().map(|p| TactileIndex {
                    frames: p.frames.len() + 1,
                    travel_mm: p.travel_mm.clone(),
                })
            })
            .collect();
        let data = serde_json::to_string(&AnswerEvent {
            id: self.id,
            answer: &answer,
            tactile,
        });
        self.log.send_modify(|log| {
            log.presses = presses;
            log.events.push(match data {
                Ok(data) => LoggedEvent {
                    name: "answer",
                    data,
                },
                Err(e) => failure(&format!("serialising the answer: {e}")),
            });
            log.done = true;
        });
    }

    pub(super) fn failed(&self, message: &str) {
        self.log.send_modify(|log| {
            log.events.push(failure(message));
            log.done = true;
        });
    }
}

fn failure(message: &str) -> LoggedEvent {
    LoggedEvent {
        name: "failed",
        data: serde_json::json!({ "error": message }).to_string(),
    }
}

#[derive(Default)]
pub(super) struct QueryStore {
    next_id: u64,
    runs: VecDeque<Arc<QueryRun>>,
}

impl QueryStore {
    /// A new question's run; the oldest finished ones are forgotten beyond [`KEPT`].
    pub(super) fn start(&mut self) -> Arc<QueryRun> {
        self.next_id += 1;
        let (log, _) = watch::channel(QueryLog::default());
        let run = Arc::new(QueryRun {
            id: self.next_id,
            log,
        });
        self.runs.push_back(run.clone());
        while self.runs.len() > KEPT {
            match self.runs.iter().position(|r| r.log.borrow().done) {
                Some(i) => drop(self.runs.remove(i)),
                None => break,
            }
        }
        run
    }

    pub(super) fn get(&self, id: u64) -> Option<Arc<QueryRun>> {
        self.runs.iter().find(|r| r.id == id).cloned()
    }
}

/// Locks the store; a poisoned lock (a panic elsewhere while holding it) is still usable
/// because every update leaves the store consistent.
pub(super) fn lock(store: &Mutex<QueryStore>) -> std::sync::MutexGuard<'_, QueryStore> {
    store.lock().unwrap_or_else(|e| e.into_inner())
}
