use super::*;
use mwd_core::conventions::DEG;

fn plan(sections: Vec<Section>) -> Plan {
    Plan {
        site: Site::default(),
        tie_on: TieOnSpec {
            md_m: 3000.0,
            tvd_m: 2000.0,
            north_m: 100.0,
            east_m: 50.0,
            inclination_deg: 90.0,
            azimuth_deg: 30.0,
        },
        sections,
        drilling: DrillingParams::default(),
    }
}

#[test]
fn a_curve_ends_at_its_target_after_dogleg_over_dls() {
    let built = plan(vec![Section::Curve {
        dls_deg_per_30m: 6.0,
        inclination_deg: 93.0,
        azimuth_deg: 30.0,
    }])
    .build()
    .expect("valid");
    // 3 deg at 6 deg/30 m: 15 m.
    assert!((built.end_md() - 3015.0).abs() < 1e-9);
    let end = built.at(3015.0);
    assert!((end.inclination - 93.0 * DEG).abs() < 1e-12);
    // A pure build (inclination up past 90 = towards the high side).
    let tf = built.section_toolface(&built.at(3007.0));
    assert!(tf.abs() < 1e-9, "build toolface {tf}");
}

#[test]
fn a_right_turn_needs_toolface_90() {
    let built = plan(vec![Section::Curve {
        dls_deg_per_30m: 3.0,
        inclination_deg: 90.0,
        azimuth_deg: 40.0,
    }])
    .build()
    .expect("valid");
    let tf = built.section_toolface(&built.at(3010.0));
    assert!((tf - 90.0 * DEG).abs() < 1e-6, "turn toolface {}", tf / DEG);
}

#[test]
fn bad_plans_are_refused_with_the_field_named() {
    let cases: Vec<(Plan, &str)> = vec![
        (
            plan(vec![Section::Hold {
                end_md_m: 2999.0,
                toolface_deg: 0.0,
            }]),
            "end_md_m",
        ),
        (
            plan(vec![Section::Curve {
                dls_deg_per_30m: 45.0,
                inclination_deg: 95.0,
                azimuth_deg: 30.0,
            }]),
            "dls_deg_per_30m",
        ),
        (
            plan(vec![Section::Curve {
                dls_deg_per_30m: f64::NAN,
                inclination_deg: 95.0,
                azimuth_deg: 30.0,
            }]),
            "dls_deg_per_30m",
        ),
        (
            plan(vec![Section::Curve {
                dls_deg_per_30m: 5.0,
                inclination_deg: 90.0,
                azimuth_deg: 30.0,
            }]),
            "nothing to build",
        ),
        (plan(vec![]), "no sections"),
    ];
    for (p, needle) in cases {
        let err = format!("{:#}", p.build().expect_err("invalid"));
        assert!(err.contains(needle), "{err}");
    }
    let mut p = plan(vec![Section::Hold {
        end_md_m: 3100.0,
        toolface_deg: 0.0,
    }]);
    p.drilling.rop_m_per_h = 0.0;
    assert!(format!("{:#}", p.build().expect_err("rop")).contains("rop_m_per_h"));
    p.drilling.rop_m_per_h = 30.0;
    p.tie_on.inclination_deg = f64::NAN;
    assert!(format!("{:#}", p.build().expect_err("nan")).contains("inclination_deg"));
}
