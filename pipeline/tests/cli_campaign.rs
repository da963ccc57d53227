//! End-to-end tests of campaigns: `sedpack run`, `resume`, `status`, `export` and `report` on
//! small real packings, including kill -9 in the middle of a job.

mod common;

use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::{fails, json, ok, path_in, sedpack, sphere_campaign, write};
use store::{ExportRow, JobResult, JobState, Store};

/// A 2 × 2 grid of sphere packings of ~60 grains; `shaking` sets how long each runs.
fn campaign(name: &str, shaking: f64) -> String {
    sphere_campaign(name, shaking, "grid:\n  material.friction: [0.0, 0.5]\nseeds: [1, 2]\n")
}

fn rows(db: &str, name: &str) -> Vec<ExportRow> {
    let rt = tokio::runtime::Runtime::new().unwrap();
    rt.block_on(async { Store::open(db).await.unwrap().export(name).await.unwrap() })
}

/// job id → porosity bits of the finished jobs.
fn porosities(db: &str, name: &str) -> Vec<(String, u64)> {
    let mut out: Vec<(String, u64)> =
        rows(db, name).iter().filter_map(|r| Some((r.job_id.clone(), r.result.as_ref()?.porosity.to_bits()))).collect();
    out.sort();
    out
}

#[test]
fn a_grid_campaign_runs_once_and_reports() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "grid.yaml", &campaign("grid", 0.05));
    let db = &path_in(dir.path(), "sedpack.db");
    let first = ok(&["run", &file, "--db", db, "--workers", "2", "--quiet"]);
    assert!(first.contains("4 job(s), 4 new"), "{first}");
    let status = json(&["status", "grid", "--db", db, "--json"]);
    assert_eq!(
        (status["jobs"].as_u64(), status["done"].as_u64(), status["pending"].as_u64()),
        (Some(4), Some(4), Some(0))
    );
    let before = porosities(db, "grid");
    // The status gives each setup's porosities (friction 0.0 first, as submitted) and their mean
    // and population std, recomputed here from the stored results.
    let results = status["results"].as_array().unwrap();
    assert_eq!(results.len(), 2, "{results:?}");
    for (result, friction) in results.iter().zip([0.0, 0.5]) {
        assert_eq!(result["setup"], format!("material.friction = {friction:?}"));
        let mut stored: Vec<f64> = rows(db, "grid")
            .iter()
            .filter(|r| r.parameters["material.friction"].as_f64() == Some(friction))
            .map(|r| r.result.as_ref().unwrap().porosity)
            .collect();
        let mut shown: Vec<f64> =
            result["porosities"].as_array().unwrap().iter().map(|n| n.as_f64().unwrap()).collect();
        stored.sort_by(f64::total_cmp);
        shown.sort_by(f64::total_cmp);
        assert_eq!(shown, stored);
        let mean = (stored[0] + stored[1]) / 2.0;
        let std = (stored[1] - stored[0]).abs() / 2.0;
        assert!((result["mean"].as_f64().unwrap() - mean).abs() < 1e-15, "{result}");
        assert!((result["std"].as_f64().unwrap() - std).abs() < 1e-15, "{result}");
    }
    let text = ok(&["status", "grid", "--db", db]);
    let line = text.lines().find(|l| l.starts_with("porosity")).unwrap_or_else(|| panic!("{text}"));
    assert!(
        line.contains("material.friction = 0.0: ")
            && line.contains(&format!("(mean {:.3} ± ", results[0]["mean"].as_f64().unwrap())),
        "{text}"
    );

    // Submitting the same campaign again adds no job and runs nothing.
    let again = ok(&["run", &file, "--db", db, "--quiet"]);
    assert!(again.contains("4 job(s), 0 new") && again.contains("0 job(s) finished now"), "{again}");
    assert_eq!(porosities(db, "grid"), before);
    // Adding a grid value adds only the new jobs.
    let wider = write(dir.path(), "grid.yaml", &campaign("grid", 0.05).replace("[0.0, 0.5]", "[0.0, 0.5, 0.3]"));
    let third = ok(&["run", &wider, "--db", db, "--quiet", "--workers", "1", "--threads", "3"]);
    assert!(third.contains("6 job(s), 2 new") && third.contains("2 job(s) finished now"), "{third}");
    let log = std::fs::read_to_string(dir.path().join("sedpack.log")).unwrap();
    let started: Vec<&str> = log.lines().filter(|l| l.contains(" started ")).collect();
    assert_eq!(started.len(), 6, "{log}");
    assert!(started[4..].iter().all(|l| l.contains("threads=3")), "--threads 3 is what the packings ran on: {log}");

    let csv = ok(&["export", "grid", "--db", db, "--format", "csv"]);
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(&header[..4], ["job_id", "state", "seed", "material.friction"]);
    assert!(header.contains(&"porosity") && header.contains(&"mean_inv_EQ") && header.contains(&"std_WFI"));
    let porosity_at = header.iter().position(|h| *h == "porosity").unwrap();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 6);
    for row in &rows {
        let n: f64 = row[porosity_at].parse().unwrap();
        assert!((0.25..0.6).contains(&n) && row[1] == "done");
    }

    let out = dir.path().join("report");
    ok(&["report", "grid", "--db", db, "--out", out.to_str().unwrap()]);
    let dataset = std::fs::read_to_string(out.join("dataset.csv")).unwrap();
    assert_eq!(dataset.lines().count(), 7, "header and one row per finished job");
    assert!(std::fs::read_to_string(out.join("report.html")).unwrap().contains("<svg"));
}

#[test]
fn only_runs_the_jobs_of_the_grid_values_asked_for_and_leaves_the_others_pending() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "only.yaml", &campaign("only", 0.05));
    let db = &path_in(dir.path(), "only.db");
    // A value no job has is refused before anything is stored.
    fails(
        &["run", &file, "--db", db, "--only", "material.friction=0.3"],
        &["--only material.friction=0.3", "no job of campaign only has material.friction = 0.3", "0.0, 0.5"],
    );
    assert!(!Path::new(db).exists() || rows(db, "only").is_empty(), "nothing stored");

    let first = ok(&["run", &file, "--db", db, "--quiet", "--only", "material.friction=0.5"]);
    assert!(
        first.contains("--only picks 2 job(s), 2 of them pending") && first.contains("2 job(s) finished now"),
        "{first}"
    );
    assert!(first.contains("2 job(s) that --only left out are pending: `sedpack resume only` runs them"), "{first}");
    let by_state = |state: JobState| -> Vec<(f64, u64)> {
        let mut out: Vec<(f64, u64)> = rows(db, "only")
            .iter()
            .filter(|r| r.state == state)
            .map(|r| (r.parameters["material.friction"].as_f64().unwrap(), r.seed))
            .collect();
        out.sort_by(|a, b| a.partial_cmp(b).unwrap());
        out
    };
    assert_eq!(by_state(JobState::Done), [(0.5, 1), (0.5, 2)]);
    assert_eq!(by_state(JobState::Pending), [(0.0, 1), (0.0, 2)]);

    // The seed is a grid value too; a key given twice takes either value.
    let second = ok(&["resume", "only", "--db", db, "--quiet", "--only", "seed=1"]);
    assert!(
        second.contains("--only picks 2 job(s), 1 of them pending") && second.contains("1 job(s) finished now"),
        "{second}"
    );
    assert_eq!(by_state(JobState::Pending), [(0.0, 2)]);
    fails(
        &["resume", "only", "--db", db, "--only", "friction=0.0"],
        &["friction is not a grid value of campaign only", "its jobs have: material.friction, seed"],
    );
    let last = ok(&["resume", "only", "--db", db, "--quiet", "--only", "seed=2", "--only", "seed=1"]);
    assert!(
        last.contains("--only picks 4 job(s), 1 of them pending") && last.contains("1 job(s) finished now"),
        "{last}"
    );
    assert!(by_state(JobState::Pending).is_empty());
}

/// A grid that gains an axis keeps the jobs it had (their ids, results) and gives them the new
/// axis's value, so that `status`, `--only` and the report group them with it.
#[test]
fn a_grid_that_gains_an_axis_labels_the_jobs_it_had_with_its_value() {
    let dir = tempfile::tempdir().unwrap();
    let db = &path_in(dir.path(), "axis.db");
    let narrow = write(dir.path(), "axis.yaml", &sphere_campaign("axis", 0.02, "seeds: [1]\n"));
    ok(&["run", &narrow, "--db", db, "--quiet"]);
    let before = porosities(db, "axis");
    assert_eq!(rows(db, "axis")[0].parameters.keys().collect::<Vec<_>>(), ["seed"]);

    // The paper's friction, 0.5, is what the first job had: it is the same job.
    let wider = write(
        dir.path(),
        "axis.yaml",
        &sphere_campaign("axis", 0.02, "grid:\n  material.friction: [0.5, 0.3]\nseeds: [1]\n"),
    );
    let text = ok(&["run", &wider, "--db", db, "--quiet"]);
    assert!(
        text.contains("2 job(s), 1 new")
            && text.contains("1 stored job(s) now carry this campaign file's grid values")
            && text.contains("1 job(s) finished now"),
        "{text}"
    );
    let stored = rows(db, "axis");
    let kept = stored.iter().find(|r| r.job_id == before[0].0).expect("the first job is kept");
    assert_eq!(kept.parameters["material.friction"].as_f64(), Some(0.5));
    assert_eq!(kept.result.as_ref().map(|r| r.porosity.to_bits()), Some(before[0].1), "its result untouched");
    let picked = ok(&["resume", "axis", "--db", db, "--quiet", "--only", "material.friction=0.5"]);
    assert!(picked.contains("--only picks 1 job(s), 0 of them pending"), "{picked}");
    let status = ok(&["status", "axis", "--db", db]);
    assert!(status.contains("material.friction = 0.5: ") && status.contains("material.friction = 0.3: "), "{status}");
    let again = ok(&["run", &wider, "--db", db, "--quiet"]);
    assert!(!again.contains("now carry"), "nothing to relabel: {again}");
}

#[test]
fn a_saved_model_predicts_what_its_formula_gives() {
    // A model file as `sedpack report` writes it, with features the §7.3 relations can give.
    let dir = tempfile::tempdir().unwrap();
    let model = write(
        dir.path(),
        "model.json",
        r#"{"name": "m", "features": ["inv_mean_EQ", "inv_std_EL"], "coefficients": [0.03, 0.002],
            "intercept": 0.28, "cv": {"folds": 10, "mae": 0.004, "r2": 0.97},
            "ranges": {"inv_mean_EQ": [1.5, 3.0], "inv_std_EL": [5.0, 10.0]}, "campaign": "c"}"#,
    );
    let predict = |sigma_el: &str| {
        let distribution = ["--mu-fl", "0.6", "--sigma-fl", "0.15", "--mu-el", "0.7", "--sigma-el", sigma_el];
        json(&[&["predict", "--model", &model, "--json"][..], &distribution].concat())
    };
    let v = predict("0.1");
    // By hand: μ_EQ = 0.6 · 0.7 = 0.42, so n = 0.03/0.42 + 0.002/0.1 + 0.28.
    let expected = 0.03 / 0.42 + 0.002 / 0.1 + 0.28;
    assert!((v["porosity"].as_f64().unwrap() - expected).abs() < 1e-12);
    assert!(v["warnings"].as_array().unwrap().is_empty());
    // σ_EL = 0.05 puts inv_std_EL = 20 outside the training range [5, 10]: a warning.
    let v = predict("0.05");
    assert!(v["warnings"][0].as_str().unwrap().contains("inv_std_EL"));
    // A CSV of measured grains gives every mixture feature: here two grains (FL, EL) of
    // (0.5, 0.8) and (0.7, 0.6), so EQ = 0.4 and 0.42, μ_EQ = 0.41; EL has σ = 0.1.
    let grains = write(dir.path(), "grains.csv", "FL,EL\n0.5,0.8\n0.7,0.6\n");
    let v = json(&["predict", "--model", &model, "--grains", &grains, "--json"]);
    let expected = 0.03 / 0.41 + 0.002 / 0.1 + 0.28;
    assert!((v["porosity"].as_f64().unwrap() - expected).abs() < 1e-12, "{v}");
}

#[test]
fn ctrl_c_checkpoints_running_jobs_and_returns_them_to_pending() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "stop.yaml", &campaign("stop", 0.6));
    let db = &path_in(dir.path(), "stop.db");
    let child = Command::new(env!("CARGO_BIN_EXE_sedpack"))
        .args(["run", &file, "--db", db, "--workers", "1", "--quiet", "--only", "seed=1"])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let rt = tokio::runtime::Runtime::new().unwrap();
    let start = Instant::now();
    while rt.block_on(async {
        let Ok(store) = Store::open(db).await else { return true };
        store.running_jobs("stop").await.map_or(true, |r| r.is_empty())
    }) {
        assert!(start.elapsed() < Duration::from_secs(60), "no job started");
        std::thread::sleep(Duration::from_millis(100));
    }
    assert!(Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap().success());
    let out = child.wait_with_output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // The command it gives continues what was asked: the jobs of seed 1.
    assert!(
        stdout.contains("interrupted: run `sedpack resume stop --only seed=1` to finish the jobs --only picks"),
        "{stdout}"
    );
    let rows = rows(db, "stop");
    assert!(rows.iter().all(|r| r.state != JobState::Running), "no job left running");
    assert!(rows.iter().any(|r| r.state == JobState::Pending), "the interrupted job is pending again");
    // The default interval (300 s) wrote no checkpoint in these seconds: the one there was
    // written on stopping, and `resume` continues from it.
    let in_progress = &json(&["status", "stop", "--db", db, "--json"])["in_progress"];
    assert_eq!(in_progress.as_array().map(|a| a.len()), Some(1), "{in_progress}");
    assert_eq!(in_progress[0]["state"].as_str(), Some("pending"), "{in_progress}");
    let simulated = in_progress[0]["checkpoint"][0].as_f64().expect("a checkpoint written on stopping");
    assert!(simulated > 0.0, "{in_progress}");
    // The checkpoint says where the packing stood: each grain of the 0.03 kg weighs what a
    // sphere between the sieves' 5.6 and 8 mm does (ρ = 2650 kg/m³), so while the generation
    // runs the share of the mass created lies between the grains times those two (at most 1);
    // while the bed shakes, its 0.6 s of shaking end within 0.6 s after the checkpoint.
    let stage = &in_progress[0]["stage"];
    let (grains, created) = (stage["grains"].as_f64().unwrap(), stage["mass_created"].as_f64().unwrap());
    let share = |d: f64| 2650.0 * std::f64::consts::PI / 6.0 * d.powi(3) / 0.03;
    match stage["phase"].as_str() {
        Some("generation") => {
            assert!((grains * share(0.0056)).min(1.0) <= created && created <= grains * share(0.008), "{stage}");
            assert!(stage["shaking_until"].is_null(), "{stage}")
        }
        Some("shaking") => {
            let until = stage["shaking_until"].as_f64().expect("the end of the shaking");
            assert!(created == 1.0 && simulated < until && until <= simulated + 0.6, "{stage}")
        }
        Some("damping") => assert!(created == 1.0 && stage["shaking_until"].is_null(), "{stage}"),
        _ => panic!("no phase: {stage}"),
    }
    let resumed = ok(&["resume", "stop", "--db", db, "--quiet"]);
    assert!(resumed.contains("4 done"), "{resumed}");
    let log = std::fs::read_to_string(dir.path().join("stop.log")).unwrap();
    assert!(log.contains("checkpoint on stopping"), "{log}");
    let from: f64 = log
        .lines()
        .find(|l| l.contains("resuming from a checkpoint"))
        .and_then(|l| l.split("simulated_time=").nth(1))
        .and_then(|t| t.split_whitespace().next()?.parse().ok())
        .unwrap_or_else(|| panic!("no resume from a checkpoint: {log}"));
    assert!((from - simulated).abs() < 1e-9, "resumed from {from} s, the checkpoint is at {simulated} s");
}

#[test]
fn a_killed_runner_resumes_from_its_checkpoint_with_identical_results() {
    let dir = tempfile::tempdir().unwrap();
    let text = campaign("killed", 0.6);
    let file = write(dir.path(), "killed.yaml", &text);
    let reference_db = &path_in(dir.path(), "reference.db");
    ok(&["run", &file, "--db", reference_db, "--workers", "2", "--quiet"]);
    let reference = porosities(reference_db, "killed");
    assert_eq!(reference.len(), 4);

    // One worker, a checkpoint every 0.2 s; killed once a job has finished and another has a
    // checkpoint.
    let db = &path_in(dir.path(), "killed.db");
    let mut child = Command::new(env!("CARGO_BIN_EXE_sedpack"))
        .args(["run", &file, "--db", db, "--workers", "1", "--quiet", "--checkpoint-interval", "0.2"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let rt = tokio::runtime::Runtime::new().unwrap();
    let start = Instant::now();
    loop {
        assert!(start.elapsed() < Duration::from_secs(120), "no checkpoint appeared");
        std::thread::sleep(Duration::from_millis(100));
        if !Path::new(db).exists() {
            continue;
        }
        let ready = rt.block_on(async {
            let Ok(store) = Store::open(db).await else { return false };
            let Ok(running) = store.running_jobs("killed").await else { return false };
            let Ok(status) = store.status("killed").await else { return false };
            let mut checkpointed = false;
            for job in &running {
                checkpointed |= store.load_checkpoint(&job.job_id).await.ok().flatten().is_some();
            }
            status.done >= 1 && checkpointed
        });
        if ready {
            break;
        }
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let running: Vec<String> =
        rows(db, "killed").into_iter().filter(|r| r.state == JobState::Running).map(|r| r.job_id).collect();
    assert_eq!(running.len(), 1, "the killed runner left its job running");
    // `status` says where that job stands: running, with the checkpoint it will resume from.
    let status = json(&["status", "killed", "--db", db, "--json"]);
    let in_progress = &status["in_progress"];
    assert_eq!(in_progress.as_array().map(|a| a.len()), Some(1), "{in_progress}");
    assert_eq!(
        (in_progress[0]["job_id"].as_str(), in_progress[0]["state"].as_str()),
        (Some(&*running[0]), Some("running"))
    );
    let simulated = in_progress[0]["checkpoint"][0].as_f64().expect("a checkpoint");
    assert!(simulated > 0.0, "{in_progress}");
    let started = in_progress[0]["started_at"].as_f64().expect("a start");
    let heard = in_progress[0]["heartbeat_at"].as_f64().expect("a heartbeat");
    assert!(heard >= started, "{in_progress}");
    let text = ok(&["status", "killed", "--db", db]);
    assert!(text.contains(&format!("checkpoint at {simulated:.2} s simulated")), "{text}");
    // The time left: for each job left, the mean wall time of the done jobs of its setup (its
    // friction; the grid's other key is the seed), less the share of their simulated time that
    // its checkpoint covers; a job whose friction has no done job is not estimated.
    let all = rows(db, "killed");
    let friction = |r: &ExportRow| r.parameters["material.friction"].to_string();
    let (mut left, mut not_estimated) = (0.0, 0);
    for job in all.iter().filter(|r| matches!(r.state, JobState::Pending | JobState::Running)) {
        let done: Vec<_> = all
            .iter()
            .filter(|r| r.state == JobState::Done && friction(r) == friction(job))
            .map(|r| r.result.as_ref().unwrap())
            .collect();
        if done.is_empty() {
            not_estimated += 1;
            continue;
        }
        let mean = |f: &dyn Fn(&JobResult) -> f64| done.iter().map(|r| f(r)).sum::<f64>() / done.len() as f64;
        let covered = if job.job_id == running[0] { (simulated / mean(&|r| r.simulated_time)).min(1.0) } else { 0.0 };
        left += mean(&|r| r.wall_time) * (1.0 - covered);
    }
    let field = |key: &str| status[key].as_f64().unwrap_or_else(|| panic!("{key}: {status}"));
    assert!((field("estimated_time_left") - left).abs() <= 1e-9 * left.max(1e-9), "{status}");
    assert_eq!(field("jobs_not_estimated"), f64::from(not_estimated), "{status}");
    assert!(text.contains("time left"), "{text}");

    // The killed runner's job, picked alone by --only, counts as pending: its runner is dead.
    let killed = all.iter().find(|r| r.job_id == running[0]).unwrap();
    let only_friction = format!("material.friction={}", killed.parameters["material.friction"]);
    let only_seed = format!("seed={}", killed.seed);
    let alone = ok(&["resume", "killed", "--db", db, "--quiet", "--only", &only_friction, "--only", &only_seed]);
    assert!(
        alone.contains("--only picks 1 job(s), 1 of them pending") && alone.contains("1 job(s) finished now"),
        "{alone}"
    );
    let resumed = ok(&["resume", "killed", "--db", db, "--quiet"]);
    assert!(resumed.contains("4 done"), "{resumed}");
    let text = ok(&["status", "killed", "--db", db]);
    assert!(!text.contains("time left"), "nothing is left: {text}");
    assert_eq!(porosities(db, "killed"), reference, "identical results, bit for bit");
    for row in rows(db, "killed") {
        assert_eq!(row.state, JobState::Done);
        assert!(row.attempts <= 2, "each job runs once, the killed one twice");
    }
    let log = std::fs::read_to_string(dir.path().join("killed.log")).unwrap();
    assert!(log.contains("requeued the job of a dead worker") && log.contains("resuming from a checkpoint"), "{log}");
    // Each checkpoint says where its packing stood, for runs watched through the log alone.
    let checkpoint = log.lines().find(|l| l.contains(" checkpoint ")).expect("a checkpoint line");
    for field in ["simulated_time=", "phase=", "grains=", "mass_created=", "contacts="] {
        assert!(checkpoint.contains(field), "{field} in {checkpoint}");
    }
}

#[test]
fn two_runners_share_the_work_without_duplicates() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "shared.yaml", &campaign("shared", 0.05).replace("seeds: [1, 2]", "seeds: [1, 2, 3]"));
    let db = &path_in(dir.path(), "shared.db");
    let spawn = || {
        Command::new(env!("CARGO_BIN_EXE_sedpack"))
            .args(["run", &file, "--db", db, "--workers", "1", "--quiet"])
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (a, b) = (spawn(), spawn());
    let (a, b) = (a.wait_with_output().unwrap(), b.wait_with_output().unwrap());
    assert!(
        a.status.success() && b.status.success(),
        "{}{}",
        String::from_utf8_lossy(&a.stderr),
        String::from_utf8_lossy(&b.stderr)
    );
    let rows = rows(db, "shared");
    assert_eq!(rows.len(), 6);
    assert!(rows.iter().all(|r| r.state == JobState::Done && r.attempts == 1), "every job claimed exactly once");
    let finished = |o: &Output| {
        let text = String::from_utf8_lossy(&o.stdout).to_string();
        let line = text.lines().find(|l| l.contains("finished now")).unwrap().to_string();
        line.split_whitespace().nth(1).unwrap().parse::<usize>().unwrap()
    };
    assert_eq!(finished(&a) + finished(&b), 6, "the two runners split the six jobs");
}

#[test]
fn failing_jobs_are_recorded_and_retried_on_request() {
    // A packing allowed 0.02 s of simulated time cannot settle, so that job fails with the
    // solver's error while the other runs.
    let dir = tempfile::tempdir().unwrap();
    let text = campaign("failing", 0.05)
        .replace("  material.friction: [0.0, 0.5]\nseeds: [1, 2]", "  solver.max_time: [30, 0.02]");
    let file = write(dir.path(), "failing.yaml", &text);
    let db = &path_in(dir.path(), "f.db");
    let out = ok(&["run", &file, "--db", db, "--quiet"]);
    assert!(out.contains("1 job(s) finished now, 1 failed now"), "{out}");
    assert!(out.contains("not converged"), "the failure is shown with its error: {out}");
    let status = json(&["status", "failing", "--db", db, "--json"]);
    assert_eq!(status["failed"], 1);
    assert!(status["failures"][0]["error"].as_str().unwrap().contains("solver.max_time = 0.02"));
    let retried = ok(&["run", &file, "--db", db, "--retry-failed", "--quiet"]);
    assert!(retried.contains("1 failed job(s) returned to pending") && retried.contains("1 failed now"), "{retried}");
}

#[test]
fn a_campaign_with_beds_too_thin_for_their_trims_says_so_before_it_runs() {
    // 30 g of spheres over 3 cm × 3 cm make a bed of 0.03 / (2650 × 0.0009 × 0.6) = 0.021 m at
    // porosity 0.4: trims of 0.004 m leave 0.013 m to evaluate, trims of 0.012 m and 0.015 m
    // (twice that: 0.024 m and 0.030 m) nothing. One warning names the file and the first thin
    // job and counts the other; the two thin jobs then fail with the evaluation's error.
    let dir = tempfile::tempdir().unwrap();
    let text = sphere_campaign("thin", 0.05, "grid:\n  evaluation.trim: [0.004, 0.012, 0.015]\n");
    let file = write(dir.path(), "thin.yaml", &text);
    let db = &path_in(dir.path(), "t.db");
    let run = sedpack(&["run", &file, "--db", db, "--quiet"]);
    let (stdout, stderr) = (String::from_utf8_lossy(&run.stdout), String::from_utf8_lossy(&run.stderr));
    assert!(run.status.success(), "{stderr}");
    let warnings: Vec<&str> = stderr.lines().filter(|l| l.starts_with("sedpack: warning: ")).collect();
    assert_eq!(warnings.len(), 1, "{stderr}");
    for part in ["thin.yaml", "about 0.0210 m high", "evaluation.trim = 0.012 m", "(and 1 more job(s) alike)"] {
        assert!(warnings[0].contains(part), "{part}: {stderr}");
    }
    assert!(stdout.contains("1 job(s) finished now, 2 failed now"), "{stdout}");
    let status = json(&["status", "thin", "--db", db, "--json"]);
    let failures = status["failures"].as_array().unwrap();
    assert_eq!(failures.len(), 2, "{status}");
    assert!(failures.iter().all(|f| f["error"].as_str().unwrap().contains("too thin for the trim")), "{status}");
    // The same campaign without the thin jobs warns of nothing.
    let fine = write(dir.path(), "fine.yaml", &text.replace("[0.004, 0.012, 0.015]", "[0.004]"));
    let run = sedpack(&["run", &fine, "--db", db, "--quiet"]);
    assert!(run.status.success() && !String::from_utf8_lossy(&run.stderr).contains("warning"));
}

#[test]
fn bad_campaigns_and_databases_are_refused_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let db = &path_in(dir.path(), "x.db");
    let empty = write(dir.path(), "empty.yaml", "name: e\ngrid:\n  material.friction: []\n");
    fails(&["run", &empty, "--db", db], &["empty.yaml:3", "grid.material.friction", "empty list"]);
    let typo = write(dir.path(), "typo.yaml", "name: t\ngrains:\n  shape: sphere\n  mas: 0.1\n");
    fails(&["run", &typo, "--db", db], &["typo.yaml:4", "grains.mas"]);
    let grid_range = write(dir.path(), "range.yaml", "name: r\ngrid:\n  material.friction: [0.5, -1.0]\n");
    fails(&["run", &grid_range, "--db", db], &["material.friction", "-1", "grid point"]);
    // The executor block: its keys, a time limit as Slurm writes it, Slurm keys with `local`.
    let executor = |name: &str, block: &str| write(dir.path(), name, &format!("name: x\nexecutor:\n{block}"));
    let typo = executor("typo-executor.yaml", "  kind: slurm\n  cpu_per_task: 2\n");
    fails(&["run", &typo, "--db", db], &["typo-executor.yaml:4", "executor.cpu_per_task", "unknown field"]);
    let time = executor("time.yaml", "  kind: slurm\n  time: 90\n");
    fails(&["run", &time, "--db", db], &["time.yaml:4", "executor.time", "HH:MM:SS or D-HH:MM:SS"]);
    let local = executor("local.yaml", "  kind: local\n  max_parallel: 4\n");
    fails(
        &["run", &local, "--db", db],
        &["local.yaml:4", "executor.max_parallel", "applies to the slurm executor only"],
    );
    let slurm = executor("slurm.yaml", "  kind: slurm\n");
    fails(&["run", &slurm, "--db", db, "--workers", "2"], &["--workers and --threads apply to the local executor"]);
    fails(&["run", &slurm, "--db", db, "--threads", "2"], &["--workers and --threads apply to the local executor"]);
    let valid = write(dir.path(), "valid.yaml", "name: valid\n");
    fails(&["run", &valid, "--db", db, "--threads", "0"], &["--threads must be at least 1"]);
    fails(&["status", "valid", "--db", db], &["valid"]);
    fails(&["pack", &valid, "--threads", "0"], &["--threads must be at least 1"]);
    let job = executor("job.yaml", "  kind: slurm\n");
    fails(&["pack", &job], &["job.yaml:2", "executor: is a campaign key"]);

    // A corrupt file and a foreign SQLite database are refused and left exactly as they were.
    let ok_campaign = write(dir.path(), "ok.yaml", &campaign("ok", 0.05));
    let corrupt = dir.path().join("corrupt.db");
    std::fs::write(&corrupt, b"this is not a database at all, just some bytes").unwrap();
    let before = std::fs::read(&corrupt).unwrap();
    fails(&["run", &ok_campaign, "--db", corrupt.to_str().unwrap()], &["corrupt.db"]);
    assert_eq!(std::fs::read(&corrupt).unwrap(), before);
    fails(&["status", "--db", dir.path().join("missing.db").to_str().unwrap()], &["missing.db", "no such database"]);
}

/// The report finds each job's size case in its stored spec: single forms of U1 stand beside
/// Eq. 17, worked by hand, and a custom sieve curve of the same sizes gets no paper model.
#[test]
fn a_report_of_single_forms_of_u1_sets_them_beside_eq_17() {
    let dir = tempfile::tempdir().unwrap();
    let db = &path_in(dir.path(), "sedpack.db");
    let u1 = sphere_campaign("u1-shapes", 0.02, "grid:\n  grains.shape: [ellipsoid, bonded-spheres]\n")
        .replace("shape: sphere", "shape: ellipsoid\n  form: {fl: 0.6, el: 0.6}")
        .replace("{sieves: [0.0056, 0.008], fractions: [1.0]}", "U1");
    let custom = u1.replace("u1-shapes", "custom-shapes").replace(
        "size: U1",
        // U1's class with its neighbours left empty: the same grains, but not Table 3's curve.
        "size: {sieves: [0.004, 0.0056, 0.008], fractions: [0.0, 1.0]}",
    );
    for (name, text) in [("u1-shapes", &u1), ("custom-shapes", &custom)] {
        let file = write(dir.path(), &format!("{name}.yaml"), text);
        ok(&["run", &file, "--db", db, "--workers", "2", "--quiet"]);
        let out = dir.path().join(name);
        ok(&["report", name, "--db", db, "--out", out.to_str().unwrap()]);
        let md = std::fs::read_to_string(out.join("report.md")).unwrap();
        assert!(md.contains("## Grain shape at equal form (Fig. 10)"), "{md}");
        // FL = EL = 0.6: EQ⁻¹ = 1/0.36, EL⁻¹ = 1/0.6: 0.019/0.36 + 0.014/0.6 + 0.278 = 0.35411.
        let row = md.lines().find(|l| l.starts_with("| all jobs | 2.78 |")).unwrap_or_else(|| panic!("{md}"));
        if name == "u1-shapes" {
            assert!(row.starts_with("| all jobs | 2.78 | 0.354 |"), "{row}");
            assert!(md.contains("Against Eq. 17: `ellipsoid`"), "{md}");
            // Each packing's row ends with its grains, simulated time and wall time, as stored.
            for r in rows(db, name) {
                let result = r.result.unwrap();
                let cells = format!("| {} | {:.2} |", result.particles, result.simulated_time);
                let packing = md.lines().find(|l| l.starts_with(&format!("| `{}", &r.job_id[..8]))).expect(&md);
                assert!(result.particles > 0 && packing.contains(&cells), "{cells} in {packing}");
            }
        } else {
            assert!(!md.contains("Eq. 17"), "{md}");
        }
    }
}
