//! docs/batch.md's Slurm script and Kubernetes Job, run as the schedulers would run them:
//! the shell script checked by `bash -n` and run once per array task, the YAML read by
//! PyYAML and its container command run once per completion index, each with `mirrorball`
//! on the PATH and a manifest of small jobs; together the tasks must do every job exactly
//! once, and the shard count in each command must be the scheduler's task count.

use crate::util::asset;
use std::path::Path;
use std::process::Command;

fn doc() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../docs/batch.md"))
        .unwrap()
}

/// The fenced block after `<!-- tested: NAME -->`.
fn block(doc: &str, name: &str) -> String {
    let marker = format!("<!-- tested: {name} -->");
    let at = doc
        .find(&marker)
        .unwrap_or_else(|| panic!("{marker} in docs/batch.md"));
    let rest = &doc[at + marker.len()..];
    let open = rest.find("```").unwrap();
    let body = &rest[open..];
    let body = &body[body.find('\n').unwrap() + 1..];
    body[..body.find("```").unwrap()].to_string()
}

/// A folder with `mirrorball` on a PATH, three jobs in `jobs.jsonl` (paths relative to it).
fn setup() -> (tempfile::TempDir, String) {
    let d = tempfile::tempdir().unwrap();
    let bin = d.path().join("bin");
    std::fs::create_dir(&bin).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_mirrorball"), bin.join("mirrorball")).unwrap();
    let city = asset("city.exr");
    let jobs: String = (0..3)
        .map(|k| {
            format!(
                "{}\n",
                serde_json::json!({"input": city, "output": format!("out_{k}.exr"), "options": "--size 8"})
            )
        })
        .collect();
    std::fs::write(d.path().join("jobs.jsonl"), jobs).unwrap();
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    (d, path)
}

/// Runs `task(k)` for every index and checks that the tasks did each job once.
fn every_job_once(dir: &Path, n: u64, task: impl Fn(u64) -> Command) {
    let mut done = Vec::new();
    for k in 0..n {
        let o = task(k).current_dir(dir).output().unwrap();
        assert!(
            o.status.success(),
            "task {k}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        for l in String::from_utf8_lossy(&o.stdout).lines() {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            assert_eq!(v["status"], "done", "{l}");
            done.push(v["job"].as_u64().unwrap());
        }
    }
    assert_eq!(done, [0, 1, 2]);
    for k in 0..3 {
        assert!(dir.join(format!("out_{k}.exr")).exists());
    }
}

#[test]
fn the_slurm_array_script_does_every_job_once() {
    let script = block(&doc(), "slurm");
    let st = Command::new("bash")
        .args(["-n", "-c", &script])
        .status()
        .unwrap();
    assert!(st.success(), "bash -n");
    let array = script
        .lines()
        .find_map(|l| l.strip_prefix("#SBATCH --array="))
        .expect("an --array line");
    let (first, last) = array.split_once('-').unwrap();
    assert_eq!(first, "0", "tasks count from 0, as --shard does");
    let n: u64 = last.parse::<u64>().unwrap() + 1;
    assert!(script.contains("--shard \"$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT\""));
    let (d, path) = setup();
    every_job_once(d.path(), n, |k| {
        let mut c = Command::new("bash");
        c.args(["-c", &script])
            .env("PATH", &path)
            .env("MANIFEST", "jobs.jsonl")
            .env("SLURM_ARRAY_TASK_ID", k.to_string())
            .env("SLURM_ARRAY_TASK_COUNT", n.to_string());
        c
    });
}

#[test]
fn the_kubernetes_indexed_job_does_every_job_once() {
    let yaml = block(&doc(), "kubernetes");
    let o = Command::new("python3")
        .args([
            "-c",
            "import sys, json, yaml; print(json.dumps(yaml.safe_load(sys.stdin)))",
        ])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .and_then(|mut c| {
            use std::io::Write;
            c.stdin.take().unwrap().write_all(yaml.as_bytes())?;
            c.wait_with_output()
        })
        .expect("python3 with PyYAML (apt-get install python3-yaml)");
    assert!(o.status.success(), "the YAML parses");
    let job: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (job["apiVersion"].as_str(), job["kind"].as_str()),
        (Some("batch/v1"), Some("Job"))
    );
    let spec = &job["spec"];
    assert_eq!(spec["completionMode"], "Indexed");
    let n = spec["completions"].as_u64().unwrap();
    let c = &spec["template"]["spec"]["containers"][0];
    assert_eq!(c["command"], serde_json::json!(["sh", "-c"]));
    let cmd = c["args"][0].as_str().unwrap();
    assert!(
        cmd.contains(&format!("--shard \"$JOB_COMPLETION_INDEX/{n}\"")),
        "{cmd}"
    );
    let mount = c["volumeMounts"][0]["mountPath"].as_str().unwrap();
    let (d, path) = setup();
    let cmd = cmd.replace(&format!("{mount}/panoramas.jsonl"), "jobs.jsonl");
    every_job_once(d.path(), n, |k| {
        let mut c = Command::new("sh");
        c.args(["-c", &cmd])
            .env("PATH", &path)
            .env("JOB_COMPLETION_INDEX", k.to_string());
        c
    });
}
