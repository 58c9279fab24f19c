//! The trial loop every benchmark shares: trial i records `trials/NNNN.mcap` and its result
//! `trials/NNNN.json` (both written under a temporary name and renamed when complete), one
//! line of `trials.jsonl` each; a stop request (Ctrl-C) ends the loop after the trial it
//! interrupts, which is marked as such; `resume` keeps the trials whose files are complete.
//! Trials run in this process, or each in a worker process ([`Exec::Workers`], up to `jobs`
//! at once): a trial whose process dies (an FMU that aborts or segfaults) is then recorded
//! as an error with the reason, and the benchmark goes on. Trial i depends only on
//! (seed, i), so the results are the same whatever the execution, and a resumed benchmark
//! sums up exactly as an uninterrupted one.

use agrisim_error::{err, Context, Result};
use agrisim_session::interrupt;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus};

/// Which trials a benchmark runs: `trials` of them, trial i seeded from (`seed`, i) and run
/// in scene i mod `scenes` (see [`scenes`](super::scenes)).
#[derive(Clone, Copy, Debug)]
pub struct TrialPlan {
    pub trials: u64,
    pub seed: u64,
    pub scenes: u64,
}

/// How trials are executed.
pub enum Exec<'a> {
    /// One after the other in this process.
    InProcess,
    /// Each in its own process, `jobs` at once; `command(i)` runs trial i and writes its
    /// files (the CLI runs itself with `--worker-trial i`, which calls [`run_one`]).
    Workers { jobs: usize, command: &'a dyn Fn(u64) -> Command },
}

/// What the loop produced.
pub struct Completed<R> {
    /// The completed trials, in order.
    pub results: Vec<R>,
    /// The trial a stop request interrupted (its result is not among `results`).
    pub interrupted: Option<u64>,
    /// Trials taken from an earlier run's files (`resume`).
    pub resumed: u64,
}

/// trials.jsonl, written a line at a time (the trials/ directory is made with it).
struct Jsonl {
    path: PathBuf,
    file: std::fs::File,
}

impl Jsonl {
    fn create(out: &Path) -> Result<Jsonl> {
        let dir = out.join("trials");
        std::fs::create_dir_all(&dir).context(|| format!("cannot create {}", dir.display()))?;
        let path = out.join("trials.jsonl");
        let file = std::fs::File::create(&path).context(|| format!("cannot create {}", path.display()))?;
        Ok(Jsonl { path, file })
    }

    fn line(&mut self, text: &str) -> Result<()> {
        writeln!(self.file, "{text}").context(|| self.path.display().to_string())
    }

    fn interrupted(&mut self, i: u64) -> Result<()> {
        self.line(&format!("{{\"trial\":{i},\"outcome\":\"interrupted\"}}"))
    }
}

fn trial_file(dir: &Path, i: u64, ext: &str) -> PathBuf {
    dir.join(format!("{i:04}.{ext}"))
}

/// Writes `bytes` to `path` through a temporary name, so `path` is complete or absent.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let part = agrisim_bus::part_path(path);
    std::fs::write(&part, bytes).context(|| format!("cannot write {}", part.display()))?;
    std::fs::rename(&part, path).context(|| format!("cannot rename {} to {}", part.display(), path.display()))
}

/// What the loop asks of a benchmark about its trials.
pub trait Trials {
    /// One trial's result, kept in trials/NNNN.json.
    type Record: Serialize + DeserializeOwned;
    /// Runs trial `i` into `mcap`.
    fn run(&self, i: u64, mcap: &Path) -> Result<Self::Record>;
    /// The result of trial `i` whose worker process died of `reason`.
    fn failed(&self, i: u64, reason: String) -> Self::Record;
    /// A result's line of trials.jsonl.
    fn line(&self, r: &Self::Record) -> String;
}

/// Runs trials `0..n` of `trials` in `out/trials/`.
pub fn run_trials<T: Trials>(
    out: &Path,
    n: u64,
    resume: bool,
    exec: Exec,
    progress: impl FnMut(u64, u64),
    trials: &T,
) -> Result<Completed<T::Record>> {
    match exec {
        Exec::InProcess => run_in_process(out, n, resume, progress, trials),
        Exec::Workers { jobs, command } => run_in_workers(out, n, resume, jobs.max(1), command, progress, trials),
    }
}

/// A worker's job: trial `i` into `out/trials/`, its result written when it completed
/// (not when a stop request cut it short).
pub fn run_one<R: Serialize>(out: &Path, i: u64, trial: impl FnOnce(u64, &Path) -> Result<R>) -> Result<()> {
    let dir = out.join("trials");
    std::fs::create_dir_all(&dir).context(|| format!("cannot create {}", dir.display()))?;
    let r = trial(i, &trial_file(&dir, i, "mcap"))?;
    if !interrupt::requested() {
        write_atomic(&trial_file(&dir, i, "json"), serde_json::to_string(&r).expect("plain struct").as_bytes())?;
    }
    Ok(())
}

fn load<R: DeserializeOwned>(json: &Path) -> Result<R> {
    let text = std::fs::read_to_string(json).context(|| format!("cannot read {}", json.display()))?;
    serde_json::from_str::<R>(&text).map_err(|e| {
        err!("{}: not a trial result of this benchmark ({e}); remove it to run the trial again", json.display())
    })
}

/// Why a worker process ended without a result.
fn death(status: ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match status.signal() {
        Some(sig) => {
            let name = match sig {
                4 => " (SIGILL)",
                6 => " (SIGABRT)",
                7 => " (SIGBUS)",
                8 => " (SIGFPE)",
                9 => " (SIGKILL)",
                11 => " (SIGSEGV)",
                15 => " (SIGTERM)",
                _ => "",
            };
            format!("the trial's process was killed by signal {sig}{name}")
        }
        None => format!("the trial's process exited with status {} without a result", status.code().unwrap_or(-1)),
    }
}

fn run_in_workers<T: Trials>(
    out: &Path,
    n: u64,
    resume: bool,
    jobs: usize,
    command: &dyn Fn(u64) -> Command,
    mut progress: impl FnMut(u64, u64),
    trials: &T,
) -> Result<Completed<T::Record>> {
    let (dir, mut jsonl) = (out.join("trials"), Jsonl::create(out)?);
    let mut done = Completed { results: vec![], interrupted: None, resumed: 0 };
    // Finished trials waiting for their turn in trials.jsonl (None: interrupted).
    let mut finished: BTreeMap<u64, Option<T::Record>> = BTreeMap::new();
    let mut running: Vec<(u64, Child)> = vec![];
    let (mut next, mut emitted) = (0u64, 0u64);
    let mut forwarded = false;
    loop {
        if interrupt::requested() && !forwarded {
            // A stop request reaches the running trials too (a terminal's Ctrl-C already
            // does; a SIGTERM to this process alone would not).
            for (_, child) in &running {
                // SAFETY: kill(2) on a child of ours that has not been waited for.
                unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
            }
            forwarded = true;
        }
        while running.len() < jobs && next < n && !interrupt::requested() {
            let (mcap, json) = (trial_file(&dir, next, "mcap"), trial_file(&dir, next, "json"));
            if resume && mcap.is_file() && json.is_file() {
                finished.insert(next, Some(load(&json)?));
                done.resumed += 1;
            } else {
                let _ = std::fs::remove_file(&json);
                let child = command(next).spawn().context(|| format!("cannot start the worker of trial {next}"))?;
                running.push((next, child));
            }
            next += 1;
        }
        if running.is_empty() && (next >= n || interrupt::requested()) && finished.is_empty() {
            break;
        }
        let mut any = false;
        let mut k = 0;
        while k < running.len() {
            match running[k].1.try_wait().context(|| format!("waiting for the worker of trial {}", running[k].0))? {
                Some(status) => {
                    let (i, _) = running.remove(k);
                    let json = trial_file(&dir, i, "json");
                    let result = if json.is_file() {
                        Some(load(&json)?)
                    } else if interrupt::requested() || status.code() == Some(130) {
                        None
                    } else {
                        let r = trials.failed(i, death(status));
                        write_atomic(&json, serde_json::to_string(&r).expect("plain struct").as_bytes())?;
                        Some(r)
                    };
                    finished.insert(i, result);
                    any = true;
                }
                None => k += 1,
            }
        }
        // In order: the next trial's result, if it is in.
        while let Some(entry) = finished.remove(&emitted) {
            match entry {
                Some(r) if done.interrupted.is_none() => {
                    jsonl.line(&trials.line(&r))?;
                    done.results.push(r);
                    progress(emitted + 1, n);
                }
                Some(_) => {}
                None => {
                    if done.interrupted.is_none() {
                        done.interrupted = Some(emitted);
                        jsonl.interrupted(emitted)?;
                    }
                }
            }
            emitted += 1;
        }
        if running.is_empty() && interrupt::requested() {
            if done.interrupted.is_none() && emitted < n {
                done.interrupted = Some(emitted);
                jsonl.interrupted(emitted)?;
            }
            break;
        }
        if running.is_empty() && next >= n && finished.is_empty() {
            break;
        }
        if !any {
            // Polling the workers' exit: wall-clock waiting, never an input to results.
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
    }
    Ok(done)
}

fn run_in_process<T: Trials>(
    out: &Path,
    n: u64,
    resume: bool,
    mut progress: impl FnMut(u64, u64),
    trials: &T,
) -> Result<Completed<T::Record>> {
    let (dir, mut jsonl) = (out.join("trials"), Jsonl::create(out)?);
    let mut done = Completed { results: vec![], interrupted: None, resumed: 0 };
    for i in 0..n {
        let (mcap, json) = (trial_file(&dir, i, "mcap"), trial_file(&dir, i, "json"));
        let earlier = if resume && mcap.is_file() && json.is_file() { Some(load::<T::Record>(&json)?) } else { None };
        let result = match earlier {
            Some(r) => {
                done.resumed += 1;
                r
            }
            None => {
                if interrupt::requested() {
                    done.interrupted = Some(i);
                    jsonl.interrupted(i)?;
                    break;
                }
                let r = trials.run(i, &mcap)?;
                if interrupt::requested() {
                    // Stopped inside this trial: its files say so, its result is not counted.
                    let _ = std::fs::remove_file(&json);
                    done.interrupted = Some(i);
                    jsonl.interrupted(i)?;
                    break;
                }
                write_atomic(&json, serde_json::to_string(&r).expect("plain struct").as_bytes())?;
                r
            }
        };
        // One line per trial as soon as it ends: a long benchmark that is killed keeps them.
        jsonl.line(&trials.line(&result))?;
        done.results.push(result);
        progress(i + 1, n);
    }
    Ok(done)
}

/// Writes `summary` to out/summary.json, with `interrupted_at_trial` when a stop request cut
/// the benchmark short (the summary then covers the completed trials).
pub fn write_summary<S: Serialize>(out: &Path, summary: &S, interrupted: Option<u64>) -> Result<()> {
    let mut v = serde_json::to_value(summary).expect("plain struct");
    if let (Some(i), Some(map)) = (interrupted, v.as_object_mut()) {
        map.insert("interrupted_at_trial".into(), i.into());
    }
    write_atomic(&out.join("summary.json"), (serde_json::to_string_pretty(&v).expect("plain value") + "\n").as_bytes())
}
