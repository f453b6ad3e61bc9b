//! `ballpit run --series/--trajectory/--every`: the CSV parsed and checked against the report,
//! the trajectory read by the extended XYZ specification (frames counted, the last one equal
//! to `--dump`), and bad requests refused before any step runs; `--record`'s bad requests.

use std::collections::BTreeMap;
use std::path::PathBuf;

use crate::common::ballpit;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("ballpit-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The pile scene in brief (gravity, restitution 0.5, balls that come to rest) for 40 steps,
/// recorded every 15: rows and frames at steps 0, 15, 30 and 40.
fn observed_run(dir: &std::path::Path) -> (serde_json::Value, String, String, String) {
    let path = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let out = ballpit(&[
        "run",
        "--scene",
        "assets/scenes/pile.ron",
        "--balls",
        "150",
        "--steps",
        "40",
        "--every",
        "15",
        "--json",
        "--series",
        &path("series.csv"),
        "--trajectory",
        &path("run.xyz"),
        "--dump",
        &path("dump.json"),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report = serde_json::from_slice(&out.stdout).unwrap();
    let read = |name: &str| std::fs::read_to_string(dir.join(name)).unwrap();
    (
        report,
        read("series.csv"),
        read("run.xyz"),
        read("dump.json"),
    )
}

/// Equal up to serde_json's parsing, which may miss the nearest double by an ulp (the files
/// themselves are written in shortest round-trip form; `tests/ase_check.py` compares bits).
fn assert_same(written: f64, reported: f64, what: &str) {
    assert!(
        (written - reported).abs() <= 1e-15 * reported.abs(),
        "{what}: {written} against {reported}"
    );
}

const COLUMNS: [&str; 12] = [
    "step",
    "time_s",
    "kinetic_energy",
    "mechanical_energy",
    "momentum_x",
    "momentum_y",
    "temperature",
    "pressure",
    "ball_collisions",
    "wall_collisions",
    "max_overlap_rel",
    "sleeping",
];

#[test]
fn the_series_and_the_trajectory_record_the_run_and_end_where_the_report_and_dump_do() {
    let dir = scratch("observe");
    let (report, series, trajectory, dump) = observed_run(&dir);
    check_series(&report, &series);
    check_trajectory(&report, &trajectory, &dump);
    std::fs::remove_dir_all(&dir).unwrap();
}

fn check_series(report: &serde_json::Value, series: &str) {
    let mut reader = csv::Reader::from_reader(series.as_bytes());
    assert_eq!(
        reader.headers().unwrap().iter().collect::<Vec<_>>(),
        COLUMNS
    );
    let rows: Vec<BTreeMap<String, f64>> = reader
        .deserialize()
        .map(|row| row.expect("every field is a number"))
        .collect();
    let steps: Vec<f64> = rows.iter().map(|row| row["step"]).collect();
    assert_eq!(steps, [0.0, 15.0, 30.0, 40.0]);
    let dt = report["dt_s"].as_f64().unwrap();
    for row in &rows {
        assert!((row["time_s"] - row["step"] * dt).abs() < 1e-6, "{row:?}");
    }
    assert!(rows[0]["pressure"].is_nan());
    assert_eq!(rows[0]["ball_collisions"], 0.0);
    // Falling balls turn height into speed: the energy the rows show moves.
    assert!(rows[3]["kinetic_energy"] != rows[0]["kinetic_energy"]);
    let last = &rows[3];
    let field = |name: &str| report[name].as_f64().unwrap();
    for (column, field_name) in [
        ("kinetic_energy", "kinetic_energy_end"),
        ("mechanical_energy", "mechanical_energy_end"),
        ("temperature", "temperature"),
        ("ball_collisions", "ball_collisions"),
        ("wall_collisions", "wall_collisions"),
        ("max_overlap_rel", "max_overlap_rel"),
        ("sleeping", "sleeping"),
    ] {
        assert_same(last[column], field(field_name), column);
    }
    assert_same(
        last["momentum_x"],
        report["momentum_end"][0].as_f64().unwrap(),
        "momentum_x",
    );
    assert_same(
        last["momentum_y"],
        report["momentum_end"][1].as_f64().unwrap(),
        "momentum_y",
    );
    // Each row's pressure is over its interval: weighted by the intervals they make the
    // report's pressure over the whole run.
    let weighted: f64 = rows
        .windows(2)
        .map(|pair| pair[1]["pressure"] * (pair[1]["time_s"] - pair[0]["time_s"]))
        .sum();
    let pressure = field("pressure");
    assert!(pressure > 0.0);
    assert!((weighted / last["time_s"] - pressure).abs() <= 1e-9 * pressure);
}

/// One extended XYZ frame as the specification defines it: a count line, a comment line of
/// `key=value` pairs (values may be quoted), and the count's lines of columns.
struct Frame {
    info: BTreeMap<String, String>,
    rows: Vec<Vec<String>>,
}

fn read_extended_xyz(text: &str) -> Vec<Frame> {
    let mut lines = text.lines();
    let mut frames = Vec::new();
    while let Some(count) = lines.next() {
        let count: usize = count.trim().parse().expect("a frame starts with its count");
        let comment = lines.next().expect("a comment line");
        let rows = (0..count)
            .map(|_| {
                let line = lines.next().expect("a line per atom");
                line.split_whitespace().map(str::to_owned).collect()
            })
            .collect();
        frames.push(Frame {
            info: parse_comment(comment),
            rows,
        });
    }
    frames
}

fn parse_comment(comment: &str) -> BTreeMap<String, String> {
    let mut info = BTreeMap::new();
    let mut rest = comment.trim();
    while !rest.is_empty() {
        let (key, after) = rest.split_once('=').expect("key=value");
        let (value, after) = match after.strip_prefix('"') {
            Some(quoted) => quoted.split_once('"').expect("a closing quote"),
            None => after.split_once(' ').unwrap_or((after, "")),
        };
        info.insert(key.trim().to_owned(), value.to_owned());
        rest = after.trim_start();
    }
    info
}

fn check_trajectory(report: &serde_json::Value, trajectory: &str, dump: &str) {
    let frames = read_extended_xyz(trajectory);
    assert_eq!(frames.len(), 4);
    let arena = &report["arena"];
    let (width, height) = (arena[0].as_f64().unwrap(), arena[1].as_f64().unwrap());
    let dt = report["dt_s"].as_f64().unwrap();
    for (frame, step) in frames.iter().zip([0.0, 15.0, 30.0, 40.0]) {
        assert_eq!(frame.rows.len(), 150);
        assert_eq!(
            frame.info["Properties"],
            "species:S:1:pos:R:3:velo:R:3:radius:R:1:mass:R:1:id:I:1"
        );
        assert_eq!(frame.info["pbc"], "F F F");
        let lattice: Vec<f64> = (frame.info["Lattice"].split(' '))
            .map(|x| x.parse().unwrap())
            .collect();
        assert_eq!(lattice[..8], [width, 0.0, 0.0, 0.0, height, 0.0, 0.0, 0.0]);
        let time: f64 = frame.info["Time"].parse().unwrap();
        assert!((time - step * dt).abs() < 1e-6);
        for (id, row) in frame.rows.iter().enumerate() {
            assert_eq!(row.len(), 10, "{row:?}");
            assert_eq!(
                (row[0].as_str(), row[3].as_str(), row[6].as_str()),
                ("X", "0", "0")
            );
            assert_eq!(row[9], id.to_string());
        }
    }
    let dump: serde_json::Value = serde_json::from_str(dump).unwrap();
    let last = &frames[3];
    assert_eq!(dump["balls"].as_array().unwrap().len(), last.rows.len());
    for (row, ball) in last.rows.iter().zip(dump["balls"].as_array().unwrap()) {
        let number = |column: usize| row[column].parse::<f64>().unwrap();
        for (column, key) in [(1, "x"), (2, "y"), (4, "vx"), (5, "vy"), (7, "r"), (8, "m")] {
            assert_same(number(column), ball[key].as_f64().unwrap(), key);
        }
    }
}

#[test]
fn bad_requests_are_refused_before_the_run_starts() {
    let dir = scratch("observe-errors");
    let missing = dir.join("no/such/folder/out");
    let missing = missing.to_str().unwrap();
    for (flag, what) in [("--series", "series"), ("--trajectory", "trajectory")] {
        let out = ballpit(&[
            "run",
            "--scene",
            "assets/scenes/head_on.ron",
            "--steps",
            "1",
            flag,
            missing,
        ]);
        assert_eq!(out.status.code(), Some(1));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.starts_with(&format!("error: {missing}: cannot write the {what}")),
            "{stderr}"
        );
        assert!(out.stdout.is_empty(), "no report: the run never started");
    }
    let out = ballpit(&[
        "run",
        "--scene",
        "assets/scenes/head_on.ron",
        "--steps",
        "1",
        "--every",
        "0",
    ]);
    assert_eq!(out.status.code(), Some(2));
    let huge = dir.join("huge.xyz");
    let out = ballpit(&[
        "run",
        "--scene",
        "assets/scenes/gas.ron",
        "--balls",
        "1000000",
        "--steps",
        "200",
        "--trajectory",
        huge.to_str().unwrap(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("a trajectory of 201 frames of 1000000 balls could reach 33.6 GB"),
        "{stderr}"
    );
    assert!(!huge.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_recording_cannot_also_be_a_screenshot_and_an_unwritable_one_fails_before_the_window() {
    let out = ballpit(&["--record", "a.gif", "--screenshot", "b.png"]);
    assert_eq!(out.status.code(), Some(2));
    let out = ballpit(&["--record", "long.gif", "--frames", "751"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        !std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("long.gif")
            .exists()
    );
    let out = ballpit(&["--record", "no/such/folder/a.gif", "--frames", "5"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    // With the toy built in, the file is refused before a window opens; without, the window.
    let expected = if cfg!(feature = "gui") {
        "error: no/such/folder/a.gif: cannot write the recording"
    } else {
        "without the `gui` feature"
    };
    assert!(stderr.contains(expected), "{stderr}");
}

#[test]
fn a_run_as_long_as_a_whole_number_of_intervals_records_each_step_once() {
    let dir = scratch("observe-whole");
    let series = dir.join("series.csv");
    let out = ballpit(&[
        "run",
        "--scene",
        "assets/scenes/head_on.ron",
        "--steps",
        "30",
        "--every",
        "15",
        "--series",
        series.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&series).unwrap();
    let steps: Vec<&str> = text
        .lines()
        .skip(1)
        .map(|row| row.split(',').next().unwrap())
        .collect();
    assert_eq!(steps, ["0", "15", "30"]);
    // A refused trajectory leaves no series behind.
    let refused = ballpit(&[
        "run",
        "--scene",
        "assets/scenes/head_on.ron",
        "--steps",
        "1",
        "--series",
        dir.join("kept.csv").to_str().unwrap(),
        "--trajectory",
        "no/such/folder/t.xyz",
    ]);
    assert_eq!(refused.status.code(), Some(1));
    assert!(!dir.join("kept.csv").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
