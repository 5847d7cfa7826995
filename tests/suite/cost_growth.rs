//! `experiment cost-growth` (issue 32, item 3): a small plan run end to end through the built
//! binary — two bumpy spheres and a real mesh, two sizes, one method per light shape — writes
//! every output with one point per workload, size and method, each with a time, a peak read
//! from the render's own `memory.json` and the estimate, which must not be below the peak.

use std::path::Path;
use std::process::Command;

#[test]
fn a_small_plan_measures_every_point_and_the_estimate_holds() {
    let out =
        Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("cost_growth-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let spot = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/models/real/spot.obj");
    let output = Command::new(env!("CARGO_BIN_EXE_penumbra"))
        .args([
            "experiment",
            "cost-growth",
            "--triangles",
            "300,1200",
            "--size",
            "32",
        ])
        .args([
            "--sizes",
            "32,48",
            "--methods",
            "hard-sv,pw2002,dbuffer",
            "--runs",
            "1",
        ])
        .args(["--render-threads", "1", "--mesh"])
        .arg(&spot)
        .arg("--out")
        .arg(&out)
        .output()
        .expect("cannot run the penumbra binary");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{stderr}");
    for f in ["cost-growth.csv", "cost-growth.json", "summary.md"]
        .into_iter()
        .map(String::from)
        .chain(
            ["cost-triangles", "cost-pixels", "memory-estimate"]
                .iter()
                .flat_map(|s| [format!("{s}.png"), format!("{s}.svg")]),
        )
    {
        let len = std::fs::metadata(out.join(&f)).map_or(0, |m| m.len());
        assert!(len > 0, "{f} missing or empty");
    }
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("cost-growth.json")).unwrap()).unwrap();
    let points = json["points"].as_array().unwrap();
    // 3 workloads × 3 methods at 32², and the first workload at 48² × 3 methods.
    assert_eq!(points.len(), 12, "{json}");
    let lights: Vec<(&str, &str)> = points
        .iter()
        .map(|p| (p["method"].as_str().unwrap(), p["light"].as_str().unwrap()))
        .collect();
    for (method, light) in [
        ("hard-sv", "rect"),
        ("pw2002", "sphere"),
        ("dbuffer", "disk"),
    ] {
        assert!(
            lights.iter().filter(|l| **l == (method, light)).count() == 4,
            "{lights:?}"
        );
    }
    // 4·s·(s − 1) triangles for s = round(√(t/4)): s = 9 and 17.
    let tris: Vec<u64> = points
        .iter()
        .map(|p| p["triangles"].as_u64().unwrap())
        .collect();
    assert_eq!(&tris[..3], &[288; 3]);
    assert_eq!(&tris[3..6], &[1088; 3]);
    assert_eq!(&tris[6..9], &[5856; 3], "spot as its scene renders it");
    for p in points {
        let seconds = p["seconds"].as_array().unwrap();
        let [median, min, max] = [0, 1, 2].map(|k| seconds[k].as_f64().unwrap());
        assert!(min > 0.0 && min <= median && median <= max, "{p}");
        if cfg!(target_os = "linux") {
            let peak = p["peak_bytes"].as_u64().expect("peak read on Linux");
            assert!(
                peak > 1 << 20 && peak <= p["estimate_bytes"].as_u64().unwrap(),
                "{p}"
            );
        }
    }
    let summary = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(summary.contains("| pw2002 | sphere |"), "{summary}");
    std::fs::remove_dir_all(&out).unwrap();
}
