//! A noise-free simulated probe at rest, through the probe's own input path
//! (x and z gyros, tool-axis rate derived from accelerometer roll) and the
//! strapdown mechanization: it must stay put (requirement: under 1 mm and
//! 1e-6 m/s over 60 s).
use host_sim::sim::{SensorModel, SensorSimulator, Trajectory};
use mwd_core::conventions::{quat_from_euler, Euler, DEG};
use mwd_core::mechanization::{NavState, ProbeInput, Strapdown, ToolAxisSource};
use mwd_core::probe_sample::ProbeSample;
use mwd_core::timing::SAMPLE_INTERVAL_S;

#[test]
fn simulated_static_probe_stays_put_for_a_minute() {
    for (roll, pitch, heading) in [
        (-0.8061, 0.5371, -150.9636),
        (35.0, -20.0, 80.0),
        (170.0, 60.0, 0.0),
    ] {
        let truth = Euler::new(roll * DEG, pitch * DEG, heading * DEG);
        let trajectory = Trajectory::paper_static(truth);
        let start = NavState::at_rest(quat_from_euler(&truth), trajectory.position);
        let mut nav = Strapdown::new(start, SAMPLE_INTERVAL_S);
        let mut input = ProbeInput::new();
        for s in
            SensorSimulator::new(trajectory, SensorModel::ideal(), SAMPLE_INTERVAL_S).take(1200)
        {
            let probe = ProbeSample::new(s.gyro.x, s.gyro.z, s.accel);
            let source = ToolAxisSource::AccelerometerRoll;
            let frame_rate = nav.frame_rate_in_body();
            let (sample, _) = input.imu_sample(&frame_rate, &probe, source, SAMPLE_INTERVAL_S);
            nav.step(&sample);
        }
        let end = nav.state();
        let drift = end.position.ned_from(&start.position).norm();
        assert!(
            drift < 1e-3,
            "attitude {roll}/{pitch}/{heading}: drift {drift} m"
        );
        assert!(
            end.velocity.norm() < 1e-6,
            "velocity {}",
            end.velocity.norm()
        );
        assert!(end.attitude.angle_to(&start.attitude) < 1e-9);
    }
}
