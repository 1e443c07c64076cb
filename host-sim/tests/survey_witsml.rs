//! `host-sim survey --witsml` read back with an XML parser: ISCWSA test
//! well #1 under "ISCWSA MWD Rev5" with a job naming the well; the
//! trajectory's namespace, version, names and uids (escaped), one station
//! per row of the survey JSON of the same run, and each station's
//! `matrixCov` equal to the JSON's NEV covariance.

mod common;

use common::s;
use std::path::Path;

const NS: &str = "http://www.witsml.org/schemas/1series";

/// Names with each character XML gives a meaning: written escaped, read
/// back as given.
const JOB: &str = r#"{ "format": "mwd-job", "version": 1,
  "site": { "latitude_deg": 60.0, "longitude_deg": 2.0, "height_m": 0.0 },
  "well": { "name": "R&D \"North\" 1", "uid": "w&1<'x'>",
            "wellbore": "<main> 'bore' & co", "wellbore_uid": "wb\"1\"" } }"#;

/// The `matrixCov` children in the 1.4.1.1 schema's order, with the index
/// of each in the JSON's covariance [nn, ee, vv, ne, nv, ev].
const VARIANCES: [(&str, usize); 6] = [
    ("varianceNN", 0),
    ("varianceNE", 3),
    ("varianceNVert", 4),
    ("varianceEE", 1),
    ("varianceEVert", 5),
    ("varianceVertVert", 2),
];

fn elements<'a, 'i>(
    node: roxmltree::Node<'a, 'i>,
) -> impl Iterator<Item = roxmltree::Node<'a, 'i>> {
    node.children().filter(|n| n.is_element())
}

fn child<'a, 'i>(node: roxmltree::Node<'a, 'i>, name: &str) -> Option<roxmltree::Node<'a, 'i>> {
    elements(node).find(|n| n.has_tag_name((NS, name)))
}

fn text_of(node: roxmltree::Node, name: &str) -> String {
    child(node, name)
        .and_then(|n| n.text())
        .unwrap_or_else(|| panic!("no <{name}> text"))
        .to_string()
}

fn number(node: roxmltree::Node) -> f64 {
    let text = node.text().expect("a number");
    text.parse()
        .unwrap_or_else(|e| panic!("{text:?} is not a number: {e}"))
}

#[test]
fn well1_trajectory_reads_back() {
    let dir = common::scratch("survey-witsml", "well1");
    let (job, xml_path, json_path) = (
        dir.join("job.json"),
        dir.join("out.xml"),
        dir.join("out.json"),
    );
    std::fs::write(&job, JOB).unwrap();
    let stations =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/iscwsa/well1_stations.csv");
    let run = common::run(&[
        "survey",
        s(&stations),
        "--error-model",
        "ISCWSA MWD Rev5",
        "--b-total-nt",
        "50000",
        "--dip-deg",
        "70",
        "--declination-deg",
        "0",
        "--job",
        s(&job),
        "--witsml",
        s(&xml_path),
        "--json",
        s(&json_path),
    ]);
    assert_eq!(run.code, Some(0), "{}", run.stderr);

    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    let json_stations = json["stations"].as_array().expect("stations");
    let xml = std::fs::read_to_string(&xml_path).unwrap();
    let doc = roxmltree::Document::parse(&xml).expect("well-formed XML");

    let root = doc.root_element();
    assert!(root.has_tag_name((NS, "trajectorys")));
    assert_eq!(root.attribute("version"), Some("1.4.1.1"));
    let traj = child(root, "trajectory").expect("a trajectory");
    assert_eq!(traj.attribute("uidWell"), Some("w&1<'x'>"));
    assert_eq!(traj.attribute("uidWellbore"), Some("wb\"1\""));
    assert_eq!(text_of(traj, "nameWell"), "R&D \"North\" 1");
    assert_eq!(text_of(traj, "nameWellbore"), "<main> 'bore' & co");

    let xml_stations: Vec<_> = elements(traj)
        .filter(|n| n.has_tag_name((NS, "trajectoryStation")))
        .collect();
    assert_eq!(xml_stations.len(), json_stations.len());
    assert!(json_stations.len() > 2);
    let md = |n| number(child(n, "md").unwrap());
    assert_eq!(number(child(traj, "mdMn").unwrap()), md(xml_stations[0]));
    assert_eq!(
        number(child(traj, "mdMx").unwrap()),
        md(*xml_stations.last().unwrap())
    );

    let mut covariances = 0;
    for (st, js) in xml_stations.iter().zip(json_stations) {
        let md_json = js["md_m"].as_f64().unwrap();
        assert!((md(*st) - md_json).abs() <= 1e-9 * md_json.abs().max(1.0));
        // the schema's sequence: matrixCov after the position and dls
        let names: Vec<&str> = elements(*st).map(|n| n.tag_name().name()).collect();
        let at = |name: &str| names.iter().position(|n| *n == name);
        assert!(at("md") < at("tvd") && at("tvd") < at("dls"), "{names:?}");
        let Some(cov) = js["nev_covariance_m2"].as_array() else {
            assert!(
                at("matrixCov").is_none(),
                "a matrixCov without a covariance"
            );
            continue;
        };
        assert_eq!(at("matrixCov"), Some(names.len() - 1), "{names:?}");
        let matrix = child(*st, "matrixCov").unwrap();
        let got: Vec<_> = elements(matrix).collect();
        assert_eq!(got.len(), VARIANCES.len());
        let mut v = [0.0; 6];
        for (node, (name, index)) in got.iter().zip(VARIANCES) {
            assert!(node.has_tag_name((NS, name)), "{:?}", node.tag_name());
            assert_eq!(node.attribute("uom"), Some("m2"));
            let want = cov[index].as_f64().unwrap();
            let value = number(*node);
            assert!(
                (value - want).abs() <= 1e-9 * want.abs().max(1e-12),
                "{name} at MD {md_json}: {value} against the JSON's {want}"
            );
            v[index] = value;
        }
        let [nn, ee, vv, ne, ..] = v;
        assert!(nn >= 0.0 && ee >= 0.0 && vv >= 0.0, "{v:?}");
        assert!(nn * ee >= ne * ne, "{v:?}");
        covariances += 1;
    }
    assert!(covariances > 0, "no station with a covariance");
}
