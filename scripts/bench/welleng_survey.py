"""One survey by welleng, as a user's script would run it: read a station
file (md_m,inc_deg,azi_deg), position it and give it the ISCWSA MWD Rev 5
covariance (welleng 0.30 names it "ISCWSA MWD Rev5.11") at the
ISCWSA #1 site, and write one CSV row per station
(north, east, TVD and the NEV variances). Used by
scripts/survey-scale-bench.sh as the reference process."""

import csv
import sys

import numpy as np
import welleng as we


def main(stations_path: str, out_path: str) -> None:
    data = np.loadtxt(stations_path, delimiter=",", skiprows=1)
    header = we.survey.SurveyHeader(
        latitude=60.0,
        G=9.80665,
        b_total=50_000.0,
        dip=72.0,
        declination=-4.0,
        azi_reference="true",
    )
    survey = we.survey.Survey(
        md=data[:, 0],
        inc=data[:, 1],
        azi=data[:, 2],
        header=header,
        error_model="ISCWSA MWD Rev5.11",
    )
    cov = survey.cov_nev
    with open(out_path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["md_m", "north_m", "east_m", "tvd_m", "var_nn", "var_ee", "var_vv"])
        for k in range(len(survey.md)):
            w.writerow(
                [survey.md[k], survey.n[k], survey.e[k], survey.tvd[k],
                 cov[k][0][0], cov[k][1][1], cov[k][2][2]]
            )


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
