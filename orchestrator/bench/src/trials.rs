//! The trial loop every benchmark shares: trial i records `trials/NNNN.mcap` and its result
//! `trials/NNNN.json` (both written under a temporary name and renamed when complete), one
//! line of `trials.jsonl` each; a stop request (Ctrl-C) ends the loop after the trial it
//! interrupts, which is marked as such; `resume` keeps the trials whose files are complete.
//! Trial i depends only on (seed, i), so a resumed benchmark sums up exactly as an
//! uninterrupted one.

use agrisim_error::{err, Context, Result};
use agrisim_session::interrupt;
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::io::Write;
use std::path::{Path, PathBuf};

/// What the loop produced.
pub struct Completed<R> {
    /// The completed trials, in order.
    pub results: Vec<R>,
    /// The trial a stop request interrupted (its result is not among `results`).
    pub interrupted: Option<u64>,
    /// Trials taken from an earlier run's files (`resume`).
    pub resumed: u64,
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

/// Runs trials `0..n` in `out/trials/`. `trial(i, mcap)` runs one trial into `mcap`;
/// `line(result)` is its trials.jsonl line.
pub fn run_trials<R: Serialize + DeserializeOwned>(
    out: &Path,
    n: u64,
    resume: bool,
    mut progress: impl FnMut(u64, u64),
    mut trial: impl FnMut(u64, &Path) -> Result<R>,
    line: impl Fn(&R) -> String,
) -> Result<Completed<R>> {
    let dir = out.join("trials");
    std::fs::create_dir_all(&dir).context(|| format!("cannot create {}", dir.display()))?;
    let jsonl_path = out.join("trials.jsonl");
    let mut jsonl = std::fs::File::create(&jsonl_path).context(|| format!("cannot create {}", jsonl_path.display()))?;
    let mut done = Completed { results: vec![], interrupted: None, resumed: 0 };
    for i in 0..n {
        let (mcap, json) = (trial_file(&dir, i, "mcap"), trial_file(&dir, i, "json"));
        let earlier = if resume && mcap.is_file() && json.is_file() {
            let text = std::fs::read_to_string(&json).context(|| format!("cannot read {}", json.display()))?;
            Some(serde_json::from_str::<R>(&text).map_err(|e| err!("{}: not a trial result of this benchmark ({e}); remove it to run the trial again", json.display()))?)
        } else {
            None
        };
        let result = match earlier {
            Some(r) => {
                done.resumed += 1;
                r
            }
            None => {
                if interrupt::requested() {
                    done.interrupted = Some(i);
                    writeln!(jsonl, "{{\"trial\":{i},\"outcome\":\"interrupted\"}}").context(|| jsonl_path.display().to_string())?;
                    break;
                }
                let r = trial(i, &mcap)?;
                if interrupt::requested() {
                    // Stopped inside this trial: its files say so, its result is not counted.
                    let _ = std::fs::remove_file(&json);
                    done.interrupted = Some(i);
                    writeln!(jsonl, "{{\"trial\":{i},\"outcome\":\"interrupted\"}}").context(|| jsonl_path.display().to_string())?;
                    break;
                }
                write_atomic(&json, serde_json::to_string(&r).expect("plain struct").as_bytes())?;
                r
            }
        };
        // One line per trial as soon as it ends: a long benchmark that is killed keeps them.
        writeln!(jsonl, "{}", line(&result)).context(|| jsonl_path.display().to_string())?;
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
