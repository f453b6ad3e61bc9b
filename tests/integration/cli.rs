//! The `ballpit` binary end to end: reports, dumps and exit codes.

use std::process::{Command, Output};

use crate::common::ballpit;

/// Runs ballpit and asserts it succeeded, showing its error output if not.
fn ballpit_ok(args: &[&str]) -> Output {
    let out = ballpit(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

const REPORT_FIELDS: [&str; 19] = [
    "steps",
    "sim_time_s",
    "ms_per_step_median",
    "ms_per_step_mean",
    "ball_collisions",
    "wall_collisions",
    "kinetic_energy_start",
    "kinetic_energy_end",
    "momentum_start",
    "momentum_end",
    "max_overlap_rel",
    "escaped",
    "pressure",
    "temperature",
    "balls",
    "dt_s",
    "mechanical_energy_change_rel",
    "speed_histogram",
    "cut_short_steps",
];

#[test]
fn run_prints_a_json_report_with_every_field() {
    let out = ballpit_ok(&[
        "run",
        "--scene",
        "assets/scenes/gas.ron",
        "--steps",
        "30",
        "--balls",
        "200",
        "--json",
    ]);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    for field in REPORT_FIELDS {
        assert!(report.get(field).is_some(), "missing {field}");
    }
    assert_eq!(report["steps"], 30);
    assert_eq!(report["balls"], 200);
    assert_eq!(report["escaped"], 0);
    assert!((report["sim_time_s"].as_f64().unwrap() - 0.5).abs() < 1e-6);
    assert!(report["ball_collisions"].as_u64().unwrap() > 0);
    assert!(report["pressure"].as_f64().unwrap() > 0.0);
    assert_eq!(report["momentum_end"].as_array().unwrap().len(), 2);
    let energy_change = report["kinetic_energy_end"].as_f64().unwrap()
        / report["kinetic_energy_start"].as_f64().unwrap()
        - 1.0;
    assert!(energy_change.abs() < 1e-9, "{energy_change}");
}

#[test]
fn run_prints_a_readable_report_by_default() {
    let out = ballpit_ok(&[
        "run",
        "--scene",
        "assets/scenes/head_on.ron",
        "--steps",
        "10",
    ]);
    let text = String::from_utf8(out.stdout).unwrap();
    for field in REPORT_FIELDS {
        assert!(
            text.lines().any(|line| line.starts_with(field)),
            "missing {field} in\n{text}"
        );
    }
    // Nothing to read as JSON: pairs as `x, y`, the histogram as rows with bars.
    assert!(!text.contains(['{', '[']), "{text}");
    let rows = text.lines().filter(|line| line.contains(" – ")).count();
    assert!(rows >= 1 && text.contains('#'), "{text}");
}

#[test]
fn dump_writes_every_ball() {
    let dir = std::env::temp_dir().join(format!("ballpit-dump-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("state.json");
    ballpit_ok(&[
        "run",
        "--scene",
        "assets/scenes/newtons_cradle.ron",
        "--steps",
        "5",
        "--json",
        "--dump",
        path.to_str().unwrap(),
    ]);
    let dump: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let balls = dump["balls"].as_array().unwrap();
    assert_eq!(balls.len(), 6);
    for (index, ball) in balls.iter().enumerate() {
        assert_eq!(ball["id"], index);
        for key in ["x", "y", "vx", "vy", "r", "m"] {
            assert!(ball[key].is_number(), "{key} in {ball}");
        }
        assert_eq!(ball["r"], 20.0);
        assert_eq!(ball["m"], 20.0);
    }
    assert!((balls[0]["x"].as_f64().unwrap() + 275.0).abs() < 1e-6);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn usage_errors_exit_2() {
    for args in [
        &["run", "--scene", "assets/scenes/gas.ron"][..],
        &["run", "--scene", "assets/scenes/gas.ron", "--steps", "-3"],
        &[
            "run",
            "--scene",
            "assets/scenes/gas.ron",
            "--steps",
            "3",
            "--dt",
            "0",
        ],
        &[
            "run",
            "--scene",
            "assets/scenes/gas.ron",
            "--steps",
            "3",
            "--dt",
            "NaN",
        ],
        &[
            "run",
            "--scene",
            "assets/scenes/gas.ron",
            "--steps",
            "3",
            "--bogus",
        ],
        &[
            "run",
            "--scene",
            "assets/scenes/gas.ron",
            "--steps",
            "3",
            "--collisions",
            "sideways",
        ],
        &["bench", "--sizes", "200", "--rounds", "0"],
        &["bench", "--pile", "--rounds", "2"],
    ] {
        let out = ballpit(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        assert!(!out.stderr.is_empty());
    }
}

#[test]
fn runtime_errors_exit_1_naming_the_cause() {
    for (args, expected) in [
        (
            &["--scene", "no/such.ron", "--steps", "1"][..],
            "no/such.ron: cannot read",
        ),
        (
            &[
                "--scene",
                "assets/scenes/head_on.ron",
                "--steps",
                "1",
                "--balls",
                "10",
            ],
            "lacks",
        ),
        (
            &[
                "--scene",
                "assets/scenes/gas.ron",
                "--steps",
                "1",
                "--balls",
                "100000000",
            ],
            "limit",
        ),
    ] {
        let out = ballpit(&[&["run"], args].concat());
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains(expected), "{args:?}: {stderr}");
    }
}

#[test]
fn bad_values_and_unwritable_files_exit_1_naming_the_file_and_line() {
    let dir = std::env::temp_dir().join(format!("ballpit-errors-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("bad.ron");
    std::fs::write(
        &scene,
        "(\n  arena: (width: 300.0, height: 200.0),\n  restitution: 3.0,\n)\n",
    )
    .unwrap();
    let scene = scene.to_str().unwrap();
    let out = ballpit(&["run", "--scene", scene, "--steps", "1"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.starts_with(&format!(
            "error: {scene}:3:16: restitution 3 is outside [0, 1]"
        )),
        "{stderr}"
    );
    let dump = dir.join("no/such/folder/out.json");
    let dump = dump.to_str().unwrap();
    let out = ballpit(&[
        "run",
        "--scene",
        "assets/scenes/head_on.ron",
        "--steps",
        "1",
        "--dump",
        dump,
    ]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.starts_with(&format!("error: {dump}: cannot write")),
        "{stderr}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_same_run_with_one_thread_or_three_is_bit_identical_in_both_modes() {
    // 30,000 balls: above the size at which the pair search runs in parallel bands.
    let dir = std::env::temp_dir().join(format!("ballpit-threads-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let dump = |mode: &str, threads: &str| {
        let path = dir.join(format!("{mode}-{threads}.json"));
        ballpit_ok(&[
            "run",
            "--scene",
            "assets/scenes/gas.ron",
            "--balls",
            "30000",
            "--steps",
            "20",
            "--json",
            "--collisions",
            mode,
            "--threads",
            threads,
            "--dump",
            path.to_str().unwrap(),
        ]);
        std::fs::read(&path).unwrap()
    };
    for mode in ["continuous", "discrete"] {
        let one = dump(mode, "1");
        assert!(one.len() > 1_000_000);
        assert!(
            one == dump(mode, "3"),
            "{mode}: one and three threads differ"
        );
        assert!(
            one == dump(mode, "1"),
            "{mode}: two runs on one thread differ"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn collisions_flag_chooses_the_mode_and_discrete_overlaps_where_continuous_does_not() {
    let run = |mode: &str| {
        let out = ballpit_ok(&[
            "run",
            "--scene",
            "assets/scenes/gas.ron",
            "--steps",
            "60",
            "--balls",
            "300",
            "--collisions",
            mode,
            "--json",
        ]);
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let (continuous, discrete) = (run("continuous"), run("discrete"));
    assert_eq!(continuous["max_overlap_rel"].as_f64(), Some(0.0));
    assert!(discrete["max_overlap_rel"].as_f64().unwrap() > 0.01);
    let histogram = &continuous["speed_histogram"];
    let counts: u64 = histogram["counts"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_u64().unwrap())
        .sum();
    assert_eq!(counts, 300);
    assert_eq!(histogram["expected"].as_array().unwrap().len(), 40);
}

#[test]
fn a_short_soak_passes() {
    // The short form of `ballpit soak` (the README gives the long one and its figures).
    let out = ballpit_ok(&[
        "soak",
        "--scenes",
        "8",
        "--steps",
        "3000",
        "--max-balls",
        "120",
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        stdout.lines().filter(|l| l.starts_with("ok ")).count(),
        8,
        "{stdout}"
    );
    assert!(stdout.contains("all 8 scenes passed"), "{stdout}");
}

#[test]
fn the_bench_runs_every_case_in_its_children() {
    let out = ballpit_ok(&[
        "bench",
        "--sizes",
        "200",
        "--steps",
        "5",
        "--all-pairs-max",
        "200",
        "--rounds",
        "2",
        "--json",
    ]);
    let rows: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let row = &rows[0];
    assert_eq!(row["balls"], 200);
    for case in [
        "one_core",
        "all_cores",
        "all_pairs",
        "continuous_one_core",
        "continuous_all_cores",
    ] {
        let median = row[case]["ms_per_step_median"].as_f64().unwrap();
        assert!(median > 0.0, "{case}: {row}");
        // Two rounds, each run: the faster is reported.
        let rounds: Vec<f64> = row[case]["rounds_ms_per_step"]
            .as_array()
            .unwrap()
            .iter()
            .map(|ms| ms.as_f64().unwrap())
            .collect();
        assert_eq!(rounds.len(), 2, "{case}: {row}");
        assert_eq!(median, rounds[0].min(rounds[1]), "{case}: {row}");
    }
    // Each child ran the mode, broad phase and threads its case asked for.
    assert_eq!(row["all_pairs"]["case"]["broad_phase"], "AllPairs");
    assert_eq!(row["one_core"]["threads"], 1);
    assert_eq!(row["continuous_one_core"]["threads"], 1);
    assert_eq!(
        row["continuous_all_cores"]["case"]["collisions"],
        "Continuous"
    );
    assert_eq!(row["all_cores"]["case"]["collisions"], "Discrete");
    assert_eq!(row["one_core"]["case"]["collisions"], "Discrete");
    assert_eq!(
        row["continuous_one_core"]["case"]["collisions"],
        "Continuous"
    );
}

#[test]
fn no_progress_bar_reaches_piped_output_and_quiet_is_accepted() {
    // The bar is drawn on stderr only when stderr is a terminal; here both are pipes.
    for quiet in [false, true] {
        let mut args = vec!["run", "--scene", "assets/scenes/gas.ron", "--steps", "20"];
        args.extend(["--balls", "100"]);
        if quiet {
            args.push("--quiet");
        }
        let out = ballpit_ok(&args);
        assert!(
            out.stderr.is_empty(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(String::from_utf8(out.stdout).unwrap().starts_with("balls"));
    }
    let soak = ballpit_ok(&["soak", "--scenes", "1", "--steps", "10", "--quiet"]);
    assert!(soak.stderr.is_empty());
}

#[test]
fn a_reader_that_goes_away_ends_the_printing_not_the_run() {
    let dir = std::env::temp_dir().join(format!("ballpit-pipe-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let dump = dir.join("state.json");
    let mut child = Command::new(env!("CARGO_BIN_EXE_ballpit"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args([
            "run",
            "--scene",
            "assets/scenes/gas.ron",
            "--steps",
            "30",
            "--dump",
        ])
        .arg(&dump)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Like `| head -0`: the reader is gone before the report is printed.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        std::fs::read_to_string(&dump)
            .unwrap()
            .contains("\"balls\"")
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
