"""Writes a station file of N stations 1 m apart (md_m,inc_deg,azi_deg):
vertical to 500 m, a build at 3 deg/30 m to 60 deg, then a 0.01 deg/m
turn, the well of host-sim/benches/survey.rs."""

import sys


def main(n: int, path: str) -> None:
    with open(path, "w") as f:
        f.write("md_m,inc_deg,azi_deg\n")
        for k in range(n):
            md = float(k)
            inc = min(max(md - 500.0, 0.0) * 3.0 / 30.0, 60.0)
            azi = (30.0 + max(md - 1100.0, 0.0) * 0.01) % 360.0
            f.write(f"{md},{inc},{azi}\n")


if __name__ == "__main__":
    main(int(sys.argv[1]), sys.argv[2])
