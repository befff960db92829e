//! Long runs as server jobs: `align`, `conformal`, `transfer` and `solid` run through
//! the `fieldtex` facade on worker threads (at most [`crate::StudioOptions::max_jobs`]
//! at once, the rest queued), each into its own folder `jobs/<id>-<kind>/` of the
//! workspace. A job's state (queued, running with stage and units done, done with its
//! files and report, failed with the facade's message, cancelled) is polled as JSON or
//! streamed as server-sent events; cancelling sets a flag that the job's
//! [`fieldtex::Progress`] reports through `cancelled()`, which the facade checks between
//! its stages (the run then stops with `Error::Cancelled` and writes nothing).

use crate::workspace::Root;
use fieldtex::Progress;
use std::collections::VecDeque;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::Instant;

/// What a job runs: the facade call with its options, paths already resolved inside
/// the workspace or the read-only roots.
pub enum JobTask {
    Align(Box<fieldtex::AlignOptions>),
    Conformal(Box<fieldtex::ConformalOptions>),
    Transfer(Box<fieldtex::TransferCommandOptions>),
    Solid(Box<fieldtex::SolidOptions>),
}

impl JobTask {
    pub fn kind(&self) -> &'static str {
        match self {
            JobTask::Align(_) => "align",
            JobTask::Conformal(_) => "conformal",
            JobTask::Transfer(_) => "transfer",
            JobTask::Solid(_) => "solid",
        }
    }
}

/// A job's visible state.
#[derive(Debug, Clone)]
struct Status {
    state: &'static str,
    stage: String,
    error: Option<String>,
    files: Vec<String>,
    report: Option<serde_json::Value>,
    seconds: f64,
}

/// One job.
pub struct Job {
    pub id: String,
    pub kind: &'static str,
    /// Output folder, relative to the workspace.
    pub out_rel: String,
    out_dir: PathBuf,
    status: Mutex<Status>,
    cancel: AtomicBool,
    done: AtomicU64,
    total: AtomicU64,
    created: Instant,
}

impl Job {
    /// The job as JSON (what the page shows).
    pub fn json(&self) -> serde_json::Value {
        let s = self.status.lock().unwrap_or_else(|e| e.into_inner()).clone();
        let total = self.total.load(Ordering::Relaxed);
        let done = self.done.load(Ordering::Relaxed).min(total.max(1));
        serde_json::json!({
            "id": self.id,
            "kind": self.kind,
            "dir": self.out_rel,
            "state": s.state,
            "stage": s.stage,
            "done": done,
            "total": total,
            "error": s.error,
            "files": s.files,
            "report": s.report,
            "seconds": if s.seconds > 0.0 { s.seconds } else { self.created.elapsed().as_secs_f64() },
            "cancel_requested": self.cancel.load(Ordering::Relaxed),
        })
    }

    /// Whether the job has ended (done, failed or cancelled).
    pub fn finished(&self) -> bool {
        matches!(
            self.status.lock().unwrap_or_else(|e| e.into_inner()).state,
            "done" | "failed" | "cancelled"
        )
    }

    /// Asks the job to stop; a queued job is cancelled at once.
    pub fn request_cancel(&self) {
        self.cancel.store(true, Ordering::SeqCst);
        let mut s = self.status.lock().unwrap_or_else(|e| e.into_inner());
        if s.state == "queued" {
            s.state = "cancelled";
            s.stage = "cancelled before it started".into();
        }
    }
}

impl Progress for Job {
    fn stage(&self, name: &str, total: u64) {
        self.status.lock().unwrap_or_else(|e| e.into_inner()).stage = name.to_string();
        self.done.store(0, Ordering::Relaxed);
        self.total.store(total, Ordering::Relaxed);
    }
    fn advance(&self, n: u64) {
        self.done.fetch_add(n, Ordering::Relaxed);
    }
    fn cancelled(&self) -> bool {
        self.cancel.load(Ordering::Relaxed)
    }
}

/// The job list and the worker pool.
pub struct Jobs {
    inner: Mutex<JobsInner>,
    wake: Condvar,
    max_queued: usize,
}

#[derive(Default)]
struct JobsInner {
    all: Vec<Arc<Job>>,
    queue: VecDeque<(Arc<Job>, JobTask)>,
    counter: u64,
}

/// Most jobs kept in the list (the oldest finished ones are forgotten beyond; their
/// folders stay in the workspace).
const MAX_LISTED: usize = 64;

impl Jobs {
    /// Starts `workers` worker threads.
    pub fn start(workers: usize, max_queued: usize) -> Arc<Self> {
        let jobs = Arc::new(Self {
            inner: Mutex::new(JobsInner::default()),
            wake: Condvar::new(),
            max_queued,
        });
        for i in 0..workers.max(1) {
            let j = jobs.clone();
            let _ = std::thread::Builder::new()
                .name(format!("studio-job-{i}"))
                .spawn(move || j.worker());
        }
        jobs
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, JobsInner> {
        self.inner.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// A fresh job id and its output folder name (`<id>-<kind>`).
    pub fn next_id(&self, kind: &str) -> (String, String) {
        let mut g = self.lock();
        g.counter += 1;
        let secs = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs());
        let id = format!("{secs}-{}", g.counter);
        let dir = format!("{id}-{kind}");
        (id, dir)
    }

    /// Queues `task` writing into `out_dir` (`jobs/<dir>` in the workspace).
    pub fn submit(
        &self,
        id: String,
        out_rel: String,
        out_dir: PathBuf,
        task: JobTask,
    ) -> Result<Arc<Job>, String> {
        let mut g = self.lock();
        if g.queue.len() >= self.max_queued {
            return Err(format!(
                "{} jobs are already waiting; cancel one or wait for it to finish",
                g.queue.len()
            ));
        }
        let job = Arc::new(Job {
            id,
            kind: task.kind(),
            out_rel,
            out_dir,
            status: Mutex::new(Status {
                state: "queued",
                stage: "waiting for a worker".into(),
                error: None,
                files: Vec::new(),
                report: None,
                seconds: 0.0,
            }),
            cancel: AtomicBool::new(false),
            done: AtomicU64::new(0),
            total: AtomicU64::new(0),
            created: Instant::now(),
        });
        g.all.push(job.clone());
        if g.all.len() > MAX_LISTED
            && let Some(pos) = g.all.iter().position(|j| j.finished())
        {
            g.all.remove(pos);
        }
        g.queue.push_back((job.clone(), task));
        drop(g);
        self.wake.notify_one();
        Ok(job)
    }

    pub fn get(&self, id: &str) -> Option<Arc<Job>> {
        self.lock().all.iter().find(|j| j.id == id).cloned()
    }

    pub fn list(&self) -> Vec<serde_json::Value> {
        self.lock().all.iter().map(|j| j.json()).collect()
    }

    fn worker(&self) {
        loop {
            let (job, task) = {
                let mut g = self.lock();
                loop {
                    if let Some(t) = g.queue.pop_front() {
                        break t;
                    }
                    g = self.wake.wait(g).unwrap_or_else(|e| e.into_inner());
                }
            };
            if job.cancel.load(Ordering::SeqCst) {
                continue;
            }
            run_job(&job, task);
        }
    }
}

fn run_job(job: &Job, task: JobTask) {
    {
        let mut s = job.status.lock().unwrap_or_else(|e| e.into_inner());
        s.state = "running";
        s.stage = "starting".into();
    }
    let t0 = Instant::now();
    let dir = job.out_dir.clone();
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| match &task {
        JobTask::Align(o) => fieldtex::align(&dir, o, job),
        JobTask::Conformal(o) => fieldtex::conformal(o, &dir, job),
        JobTask::Transfer(o) => fieldtex::transfer_files(&dir, o, job),
        JobTask::Solid(o) => fieldtex::solid(&dir, o, job),
    }));
    let mut s = job.status.lock().unwrap_or_else(|e| e.into_inner());
    s.seconds = t0.elapsed().as_secs_f64();
    match result {
        Ok(Ok(report)) => {
            s.state = "done";
            s.stage = "done".into();
            s.files = list_files(&dir);
            s.report = serde_json::from_str(&report.to_json_pretty()).ok();
        }
        Ok(Err(fieldtex::Error::Cancelled)) => {
            s.state = "cancelled";
            s.stage = "cancelled (no outputs written)".into();
        }
        Ok(Err(e)) => {
            s.state = "failed";
            s.error = Some(e.to_string());
        }
        Err(_) => {
            s.state = "failed";
            s.error =
                Some("internal error (a panic) inside the pipeline; see the server log".into());
        }
    }
}

/// Plain files directly in `dir` (no links, no folders), names sorted.
pub fn list_files(dir: &std::path::Path) -> Vec<String> {
    let mut out: Vec<String> = std::fs::read_dir(dir)
        .map(|it| {
            it.flatten()
                .filter(|e| e.file_type().is_ok_and(|t| t.is_file()))
                .filter_map(|e| e.file_name().into_string().ok())
                .filter(|n| !n.starts_with('.'))
                .collect()
        })
        .unwrap_or_default();
    out.sort();
    out
}

/// The files of a finished job, checked to be inside the workspace (the folder is
/// re-canonicalised, so a folder swapped for a link is refused).
pub fn job_files(root: &Root, job: &Job) -> Result<Vec<String>, (u16, String)> {
    let dir = root.join_checked(&job.out_rel)?;
    let canon = dir.canonicalize().map_err(|_| (404, format!("{} has no outputs", job.out_rel)))?;
    if !canon.starts_with(&root.dir) {
        return Err((403, format!("{} resolves outside the workspace", job.out_rel)));
    }
    Ok(list_files(&canon).into_iter().map(|n| format!("{}/{n}", job.out_rel)).collect())
}
