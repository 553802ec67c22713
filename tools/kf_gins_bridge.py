#!/usr/bin/env python3
"""Bridge between a simulated bag of ours and KF-GINS (i2Nav-WHU's loosely-coupled
GNSS/INS EKF), so that both filters run on the same data and are scored against the
same truth (issue 14, item 6; tests/data/navigation_grade_rtk.yaml is the scenario).

  kf_gins_bridge.py export BAG --out DIR --params P.yaml [--params P2.yaml ...]
                    [--start-s 1.0]
      Writes into DIR, from the bag:
      imu.txt     KF-GINS's IMU file: GPS time of week (s), then the angle (rad) and
                  velocity (m/s) increments over the interval ending at that time, in
                  KF-GINS's body frame (forward-right-down). The increments come from the
                  bag's instantaneous /imu samples by the trapezoidal rule, as our engine
                  forms them (src/ins/mechanization.rs ImuIncrement::from_samples), and
                  are turned from our FLU into FRD: (x, -y, -z).
      gnss.txt    KF-GINS's GNSS file from /gnss/fix: time of week, latitude, longitude
                  (deg), ellipsoidal height (m), and the 1-sigma north, east, down (m) of
                  the fix's covariance (ENU in the message; its correlations are lost:
                  KF-GINS takes a diagonal).
      truth.nav   /ground_truth in KF-GINS's navigation format: week, time of week,
                  latitude, longitude, height, v north/east/down, roll, pitch, yaw (deg,
                  NED/FRD, yaw 0-360 clockwise from north).
      kf-gins.yaml  KF-GINS's configuration: the files above, the output folder DIR, the
                  IMU noise and lever arm taken from our parameter files (--params, as
                  `gnss_ins replay` merges them: later wins), and the initial state from
                  the truth at --start-s (scenario time) with small sigmas. KF-GINS needs
                  an initial state; our filter finds its own (levelling, heading from the
                  fixes' course), so KF-GINS starts with an advantage.
      Times: KF-GINS wants GPS seconds of week. The bag's stamps are UTC (ROS time),
      GPS - UTC = 18 s (src/sim/scenario_clock.rs), so tow = (stamp + 18 s - GPS epoch)
      mod one week, computed in integer nanoseconds.

  kf_gins_bridge.py compare BAG [--ours CSV ...] [--kfgins NAV ...] [--from-s T]
      Scores each solution against /ground_truth at the truth's epochs (10 Hz) where
      every solution has an output (from the latest first output on, or from --from-s):
      3D, horizontal and vertical position RMSE, velocity RMSE, roll/pitch/yaw RMSE and
      mean, split between fixes available and outages, and the error at the end of each
      GNSS outage (the outages are read from /ground_truth/environment). All three refer
      to the same point: the IMU centre (/ground_truth is the true IMU position; our
      replay CSV is the engine's navigation state, the IMU's; KF-GINS outputs the IMU's).
      Our CSV's attitude is ENU/FLU, KF-GINS's NED/FRD (both Z-Y-X Euler angles):
      yaw_ENU = 90 deg - yaw_NED, pitch_ENU = -pitch_NED (a positive rotation about the
      left axis lowers the nose), roll the same.

Runs with the project venv (rosbags, numpy, PyYAML): .venv/bin/python tools/kf_gins_bridge.py
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
from pathlib import Path

import numpy as np
import yaml
from rosbags.highlevel import AnyReader

NS = 1_000_000_000
GPS_EPOCH_UNIX_S = 315_964_800
GPS_UTC_LEAP_S = 18
WEEK_S = 604_800
MICRO_G = 9.80665e-6  # m/s^2 (the parameter manual's ug)
MGAL = 1e-5  # m/s^2

A = 6_378_137.0
F = 1.0 / 298.257_223_563
E2 = F * (2.0 - F)

IMU_TOPIC = '/imu'
FIX_TOPIC = '/gnss/fix'
TRUTH_TOPIC = '/ground_truth'
DATUM_TOPIC = '/ground_truth/datum'
ENV_TOPIC = '/ground_truth/environment'


# ---------------------------------------------------------------- geodesy and attitude

def llh_to_ecef(lat: np.ndarray, lon: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Geodetic (rad, rad, m) to ECEF (m), rows of points."""
    sl, cl, so, co = np.sin(lat), np.cos(lat), np.sin(lon), np.cos(lon)
    rn = A / np.sqrt(1.0 - E2 * sl * sl)
    return np.stack([(rn + h) * cl * co, (rn + h) * cl * so, (rn * (1.0 - E2) + h) * sl], axis=-1)


def rot_ecef_to_enu(lat: float, lon: float) -> np.ndarray:
    sl, cl, so, co = math.sin(lat), math.cos(lat), math.sin(lon), math.cos(lon)
    return np.array([[-so, co, 0.0], [-sl * co, -sl * so, cl], [cl * co, cl * so, sl]])


def llh_to_enu(lat, lon, h, datum) -> np.ndarray:
    """Geodetic (rad) to ENU (m) at the datum (lat, lon, h in rad, rad, m), as
    src/earth.rs llh_to_enu."""
    d = llh_to_ecef(np.array(datum[0]), np.array(datum[1]), np.array(datum[2]))
    return (llh_to_ecef(lat, lon, h) - d) @ rot_ecef_to_enu(datum[0], datum[1]).T


def ecef_to_llh(x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """ECEF (m) to geodetic (rad, rad, m), by iteration (sub-millimetre)."""
    p = np.hypot(x[..., 0], x[..., 1])
    lon = np.arctan2(x[..., 1], x[..., 0])
    lat = np.arctan2(x[..., 2], p * (1.0 - E2))
    h = np.zeros_like(p)
    for _ in range(10):
        sl = np.sin(lat)
        rn = A / np.sqrt(1.0 - E2 * sl * sl)
        h = p / np.cos(lat) - rn
        lat = np.arctan2(x[..., 2], p * (1.0 - E2 * rn / (rn + h)))
    return lat, lon, h


def enu_to_llh(enu: np.ndarray, datum) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    d = llh_to_ecef(np.array(datum[0]), np.array(datum[1]), np.array(datum[2]))
    return ecef_to_llh(d + enu @ rot_ecef_to_enu(datum[0], datum[1]))


def quat_to_matrix(q: np.ndarray) -> np.ndarray:
    """Rotation matrices of quaternions (rows x, y, z, w), body-to-nav."""
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], -1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], -1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def euler_zyx(c: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Roll, pitch, yaw (rad) of body-to-nav matrices, C = Rz(yaw) Ry(pitch) Rx(roll)."""
    roll = np.arctan2(c[:, 2, 1], c[:, 2, 2])
    pitch = np.arcsin(np.clip(-c[:, 2, 0], -1.0, 1.0))
    yaw = np.arctan2(c[:, 1, 0], c[:, 0, 0])
    return roll, pitch, yaw


def wrap_deg(x: np.ndarray) -> np.ndarray:
    return (x + 180.0) % 360.0 - 180.0


# ---------------------------------------------------------------- time

def tow_of_stamp_ns(stamp_ns: int) -> tuple[int, float]:
    """GPS week and time of week (s) of a UTC stamp (ns since 1970)."""
    gps_ns = stamp_ns + GPS_UTC_LEAP_S * NS - GPS_EPOCH_UNIX_S * NS
    week, rest = divmod(gps_ns, WEEK_S * NS)
    return week, rest / NS


def stamp_ns(header) -> int:
    return int(header.stamp.sec) * NS + int(header.stamp.nanosec)


# ---------------------------------------------------------------- reading the bag

def read_bag(bag: Path, topics: set[str]) -> dict[str, list]:
    """(stamp ns, message) per topic, in log order."""
    out: dict[str, list] = {t: [] for t in topics}
    with AnyReader([bag]) as reader:
        conns = [c for c in reader.connections if c.topic in topics]
        for conn, _, raw in reader.messages(connections=conns):
            msg = reader.deserialize(raw, conn.msgtype)
            out[conn.topic].append((stamp_ns(msg.header), msg))
    return out


class Truth:
    """/ground_truth on the scenario time axis (s after the datum's stamp)."""

    def __init__(self, msgs: dict[str, list]):
        (t0_ns, datum), = msgs[DATUM_TOPIC][:1]
        self.t0_ns = t0_ns
        self.datum = (math.radians(datum.latitude), math.radians(datum.longitude), datum.altitude)
        rows = msgs[TRUTH_TOPIC]
        self.t = np.array([(s - t0_ns) / NS for s, _ in rows])
        self.enu = np.array([[m.pose.pose.position.x, m.pose.pose.position.y,
                              m.pose.pose.position.z] for _, m in rows])
        q = np.array([[m.pose.pose.orientation.x, m.pose.pose.orientation.y,
                       m.pose.pose.orientation.z, m.pose.pose.orientation.w] for _, m in rows])
        self.c_nb = quat_to_matrix(q)  # FLU -> ENU
        v_b = np.array([[m.twist.twist.linear.x, m.twist.twist.linear.y,
                         m.twist.twist.linear.z] for _, m in rows])
        self.v_enu = np.einsum('kij,kj->ki', self.c_nb, v_b)
        roll, pitch, yaw = euler_zyx(self.c_nb)
        self.rpy_enu_deg = np.degrees(np.stack([roll, pitch, yaw], -1))
        self.week, self.tow0 = tow_of_stamp_ns(t0_ns)
        self.outages = outages(msgs.get(ENV_TOPIC, []), t0_ns, self.t[-1])

    def key(self) -> np.ndarray:
        return np.round(self.t * 1000).astype(np.int64)


def outages(env_msgs: list, t0_ns: int, t_end: float) -> list[tuple[float, float]]:
    """Spans (scenario s) whose environment is 'outage'."""
    spans, start = [], None
    for s, msg in env_msgs:
        t = (s - t0_ns) / NS
        name = msg.status[0].message if msg.status else ''
        if name == 'outage' and start is None:
            start = t
        elif name != 'outage' and start is not None:
            spans.append((start, t))
            start = None
    if start is not None:
        spans.append((start, t_end))
    return spans


# ---------------------------------------------------------------- parameters

def load_params(paths: list[Path]) -> dict[str, object]:
    """Dotted keys of ROS 2 parameter files (nested or dotted), later files winning."""
    merged: dict[str, object] = {}

    def flatten(prefix: str, node: object) -> None:
        if isinstance(node, dict):
            for k, v in node.items():
                flatten(f'{prefix}.{k}' if prefix else str(k), v)
        else:
            merged[prefix] = node

    for path in paths:
        doc = yaml.safe_load(path.read_text()) or {}
        for node in doc.values():
            flatten('', node.get('ros__parameters', {}))
    return merged


def kf_gins_noise(p: dict[str, object]) -> dict:
    """KF-GINS's imunoise and initial bias sigmas from our imu.* keys.

    Our gyro bias is a random constant (imu.gyro_bias_deg_per_h, initial sigma) plus a
    Gauss-Markov drift (gyro_markov_sigma, correlation time); KF-GINS has one
    Gauss-Markov state: its steady sigma gbstd is our drift's (same Q = 2 sigma^2 / T) and
    its initial sigma (initbgstd) the root sum square of both. The accelerometer bias is
    one Gauss-Markov state in both. KF-GINS has one correlation time for every bias and
    scale factor: our gyro drift's (the others are reported when they differ). A state
    whose own time T differs keeps its driving noise Q = 2 sigma^2 / T there: its steady
    sigma becomes sigma * sqrt(T_kfgins / T), its initial sigma stays sigma. (Copying
    sigma unchanged gave the consumer-MEMS hour's accelerometer bias, 30 mg over 10 h,
    120 times our process noise at KF-GINS's 300 s.)"""
    g = lambda k: float(p[f'imu.{k}'])
    times = {k: g(k) for k in ('gyro_markov_correlation_time_s',
                                'accel_bias_correlation_time_s',
                                'scale_factor_correlation_time_s')}
    if len(set(times.values())) > 1:
        print(f'note: KF-GINS has one correlation time; ours are {times}; '
              f'taking gyro_markov_correlation_time_s', file=sys.stderr)
    t_kf = times['gyro_markov_correlation_time_s']
    same_q = lambda sigma, t: sigma * math.sqrt(t_kf / t)
    arw = g('gyro_arw_deg_per_sqrt_h')
    vrw = g('accel_vrw_ug_per_sqrt_hz') * MICRO_G * 60.0  # m/s/sqrt(h)
    gb = g('gyro_markov_sigma_deg_per_h')
    gb0 = math.hypot(g('gyro_bias_deg_per_h'), gb)
    ab = g('accel_bias_ug') * MICRO_G / MGAL
    gs, as_ = g('gyro_scale_factor_ppm'), g('accel_scale_factor_ppm')
    return {
        'imunoise': {'arw': [arw] * 3, 'vrw': [vrw] * 3, 'gbstd': [gb] * 3,
                     'abstd': [same_q(ab, times['accel_bias_correlation_time_s'])] * 3,
                     'gsstd': [same_q(gs, times['scale_factor_correlation_time_s'])] * 3,
                     'asstd': [same_q(as_, times['scale_factor_correlation_time_s'])] * 3,
                     'corrtime': t_kf / 3600.0},
        'initbgstd': [gb0] * 3,
        'initbastd': [ab] * 3,
        'initsgstd': [gs] * 3,
        'initsastd': [as_] * 3,
        'scale_factor_states': bool(p.get('imu.scale_factor_states', False)),
    }


# ---------------------------------------------------------------- export

def export(args: argparse.Namespace) -> int:
    out: Path = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    msgs = read_bag(args.bag, {IMU_TOPIC, FIX_TOPIC, TRUTH_TOPIC, DATUM_TOPIC, ENV_TOPIC})
    truth = Truth(msgs)
    params = load_params(args.params)
    noise = kf_gins_noise(params)
    lever_flu = [float(x) for x in params.get('mounting.antenna_lever_arm_m', [0.0] * 3)]
    lever_frd = [lever_flu[0], -lever_flu[1], -lever_flu[2]]

    # IMU increments, trapezoidal, FLU -> FRD.
    imu = msgs[IMU_TOPIC]
    t_ns = np.array([s for s, _ in imu], dtype=np.int64)
    w = np.array([[m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z] for _, m in imu])
    f = np.array([[m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z]
                  for _, m in imu])
    dt = np.diff(t_ns) / NS
    flip = np.array([1.0, -1.0, -1.0])
    if args.increments == 'trapezoid':
        dtheta = 0.5 * (w[1:] + w[:-1]) * dt[:, None] * flip
        dvel = 0.5 * (f[1:] + f[:-1]) * dt[:, None] * flip
    else:  # 'end-sample': the sample at the interval's end held over it (a dt/2 lag)
        dtheta = w[1:] * dt[:, None] * flip
        dvel = f[1:] * dt[:, None] * flip
    weeks = set()
    with open(out / 'imu.txt', 'w') as fh:
        for k in range(len(dt)):
            week, tow = tow_of_stamp_ns(int(t_ns[k + 1]))
            weeks.add(week)
            fh.write(f'{tow:.6f} ' + ' '.join(f'{x:.15e}' for x in dtheta[k]) + ' '
                     + ' '.join(f'{x:.15e}' for x in dvel[k]) + '\n')
    if len(weeks) != 1:
        print(f'warning: the IMU spans GPS weeks {sorted(weeks)}', file=sys.stderr)

    # Fixes: std north, east, down from the ENU covariance's diagonal.
    fix_rows = []
    with open(out / 'gnss.txt', 'w') as fh:
        for s, m in msgs[FIX_TOPIC]:
            if m.status.status < 0:
                continue
            cov = np.asarray(m.position_covariance, dtype=float).reshape(3, 3)
            _, tow = tow_of_stamp_ns(s)
            fh.write(f'{tow:.6f} {m.latitude:.11f} {m.longitude:.11f} {m.altitude:.5f} '
                     f'{math.sqrt(cov[1, 1]):.5f} {math.sqrt(cov[0, 0]):.5f} '
                     f'{math.sqrt(cov[2, 2]):.5f}\n')
            fix_rows.append(((s - truth.t0_ns) / NS, m.latitude, m.longitude, m.altitude,
                             math.sqrt(cov[0, 0]), math.sqrt(cov[1, 1]), math.sqrt(cov[2, 2])))

    # Truth in KF-GINS's format (NED / FRD).
    lat, lon, h = enu_to_llh(truth.enu, truth.datum)
    v = truth.v_enu
    roll, pitch_enu, yaw_enu = truth.rpy_enu_deg.T
    pitch = -pitch_enu
    yaw_ned = (90.0 - yaw_enu) % 360.0
    with open(out / 'truth.nav', 'w') as fh:
        for k in range(len(truth.t)):
            tow = truth.tow0 + truth.t[k]
            fh.write(f'{truth.week} {tow:.6f} {math.degrees(lat[k]):.11f} '
                     f'{math.degrees(lon[k]):.11f} {h[k]:.5f} {v[k, 1]:.6f} {v[k, 0]:.6f} '
                     f'{-v[k, 2]:.6f} {roll[k]:.8f} {pitch[k]:.8f} {yaw_ned[k]:.8f}\n')

    # Fix errors against the true antenna (a check of the scenario's RTK grade).
    key = truth.key()
    index = {int(kk): i for i, kk in enumerate(key)}
    lever = np.array(lever_flu)
    errs, sig = [], []
    for t, la, lo, al, se, sn, su in fix_rows:
        i = index.get(int(round(t * 1000)))
        if i is None:
            continue
        ant = truth.enu[i] + truth.c_nb[i] @ lever
        e = llh_to_enu(np.radians(la), np.radians(lo), al, truth.datum) - ant
        errs.append(e)
        sig.append((se, sn, su))
    errs, sig = np.array(errs), np.array(sig)
    print(f'fixes: {len(fix_rows)}; error vs the true antenna E/N/U RMS '
          f'{np.sqrt((errs ** 2).mean(0)).round(4).tolist()} m, mean '
          f'{errs.mean(0).round(4).tolist()} m; reported sigma E/N/U RMS '
          f'{np.sqrt((sig ** 2).mean(0)).round(4).tolist()} m')

    # Configuration: initial state from the truth at start_s.
    i0 = int(np.searchsorted(truth.t, args.start_s - 1e-6))
    t_start = truth.t[i0]
    cfg = {
        'imupath': str(out / 'imu.txt'),
        'gnsspath': str(out / 'gnss.txt'),
        'outputpath': str(out),
        'imudatalen': 7,
        'imudatarate': int(round(1.0 / np.median(dt))),
        'starttime': round(float(truth.tow0 + t_start), 6),
        'endtime': -1,
        'initpos': [math.degrees(lat[i0]), math.degrees(lon[i0]), float(h[i0])],
        'initvel': [float(v[i0, 1]), float(v[i0, 0]), float(-v[i0, 2])],
        'initatt': [float(roll[i0]), float(pitch[i0]), float(yaw_ned[i0])],
        'initgyrbias': [0, 0, 0],
        'initaccbias': [0, 0, 0],
        'initgyrscale': [0, 0, 0],
        'initaccscale': [0, 0, 0],
        # KF-GINS's demo sigmas (its dataset/kf-gins.yaml): the state is the truth.
        'initposstd': [0.005, 0.004, 0.008],
        'initvelstd': [0.003, 0.004, 0.004],
        'initattstd': [0.003, 0.003, 0.023],
        'initbgstd': noise['initbgstd'],
        'initbastd': noise['initbastd'],
        'initsgstd': noise['initsgstd'],
        'initsastd': noise['initsastd'],
        'imunoise': noise['imunoise'],
        'antlever': lever_frd,
    }
    header = ('# KF-GINS configuration written by tools/kf_gins_bridge.py export from\n'
              f'# {args.bag} with the noise and lever arm of: '
              + ', '.join(str(p) for p in args.params) + '\n'
              f'# Start at scenario time {t_start:.3f} s (GPS week {truth.week}); initial '
              'state = the truth there.\n')
    if not noise['scale_factor_states']:
        header += ('# Note: our imu.scale_factor_states is off; KF-GINS always carries '
                   'the scale-factor states.\n')
    (out / 'kf-gins.yaml').write_text(header + yaml.safe_dump(cfg, sort_keys=False,
                                                              default_flow_style=None))
    print(f'wrote {out}/imu.txt ({len(dt)} increments), gnss.txt ({len(fix_rows)} fixes), '
          f'truth.nav ({len(truth.t)} epochs), kf-gins.yaml (start {t_start:.3f} s = tow '
          f'{cfg["starttime"]:.3f}); outages {truth.outages}')
    return 0


# ---------------------------------------------------------------- compare

class Track:
    """A solution on the scenario time axis: ENU position (m), ENU velocity, rpy ENU/FLU."""

    def __init__(self, label: str, t: np.ndarray, lat, lon, h, v_enu, rpy_enu_deg, datum):
        order = np.argsort(t, kind='stable')
        self.label = label
        self.t = t[order]
        self.enu = llh_to_enu(np.radians(lat[order]), np.radians(lon[order]), h[order], datum)
        self.v = v_enu[order]
        self.rpy = rpy_enu_deg[order]
        self.key = np.round(self.t * 1000).astype(np.int64)


def read_ours(path: Path, truth: Truth) -> Track:
    """Our replay CSV (t_s is UNIX time: the stamps')."""
    rows = np.genfromtxt(path, delimiter=',', names=True)
    t = (rows['t_s'] - truth.t0_ns // NS) - (truth.t0_ns % NS) / NS
    v = np.stack([rows['v_e_mps'], rows['v_n_mps'], rows['v_u_mps']], -1)
    rpy = np.stack([rows['roll_deg'], rows['pitch_deg'], rows['yaw_deg']], -1)
    return Track(path.stem, t, rows['lat_deg'], rows['lon_deg'], rows['height_m'], v, rpy,
                 truth.datum)


def read_kfgins(path: Path, truth: Truth) -> Track:
    """KF-GINS's navresult: week (0), tow, lat, lon, h, vn, ve, vd, roll, pitch, yaw (NED)."""
    d = np.loadtxt(path)
    t = d[:, 1] - truth.tow0
    v = np.stack([d[:, 6], d[:, 5], -d[:, 7]], -1)
    rpy = np.stack([d[:, 8], -d[:, 9], wrap_deg(90.0 - d[:, 10])], -1)
    return Track(f'kfgins:{path.parent.name}', t, d[:, 2], d[:, 3], d[:, 4], v, rpy, truth.datum)


def rms(x: np.ndarray) -> float:
    return float(np.sqrt(np.mean(x ** 2))) if len(x) else float('nan')


def compare(args: argparse.Namespace) -> int:
    msgs = read_bag(args.bag, {TRUTH_TOPIC, DATUM_TOPIC, ENV_TOPIC})
    truth = Truth(msgs)
    tracks = [read_ours(p, truth) for p in args.ours] + [read_kfgins(p, truth) for p in args.kfgins]
    if not tracks:
        print('nothing to compare', file=sys.stderr)
        return 2
    tkey = truth.key()
    common = set(tkey.tolist())
    for tr in tracks:
        common &= set(tr.key.tolist())
    start = max(tr.t[0] for tr in tracks)
    if args.from_s is not None:
        start = max(start, args.from_s)
    keys = np.array(sorted(k for k in common if k >= round(start * 1000)), dtype=np.int64)
    ti = np.searchsorted(tkey, keys)
    t = truth.t[ti]
    in_outage = np.zeros(len(t), dtype=bool)
    for a, b in truth.outages:
        in_outage |= (t >= a) & (t < b)
    print(f'epochs: {len(keys)} truth epochs from {t[0]:.1f} s to {t[-1]:.1f} s '
          f'(scenario time), {in_outage.sum()} of them in GNSS outages {truth.outages}')
    hdr = (f'{"solution":<22} {"3D":>7} {"horiz":>7} {"vert":>7} {"vel":>7} {"roll":>7} '
           f'{"pitch":>7} {"yaw":>7} {"yaw_mean":>8} {"3D_max":>7} {"3D_gnss":>7} '
           f'{"3D_out":>7} {"yaw_gnss":>8}')
    print('RMSE (m, m/s, deg) over those epochs; _gnss: epochs with fixes, _out: in outages')
    print(hdr)
    per_track = []
    dumps = []
    for tr in tracks:
        si = np.searchsorted(tr.key, keys)
        de = tr.enu[si] - truth.enu[ti]
        dv = tr.v[si] - truth.v_enu[ti]
        da = tr.rpy[si] - truth.rpy_enu_deg[ti]
        da[:, 2] = wrap_deg(da[:, 2])
        e3 = np.linalg.norm(de, axis=1)
        eh = np.linalg.norm(de[:, :2], axis=1)
        g = ~in_outage
        print(f'{tr.label:<22} {rms(e3):7.3f} {rms(eh):7.3f} {rms(de[:, 2]):7.3f} '
              f'{rms(np.linalg.norm(dv, axis=1)):7.4f} {rms(da[:, 0]):7.4f} '
              f'{rms(da[:, 1]):7.4f} {rms(da[:, 2]):7.4f} {da[:, 2].mean():8.4f} '
              f'{e3.max():7.3f} {rms(e3[g]):7.3f} {rms(e3[~g]):7.3f} {rms(da[g, 2]):8.4f}')
        per_track.append((tr, de, da, e3, eh))
        dumps.append((tr.label, de, dv, da))
    print('error at the end of each outage (last common epoch before the fixes return): '
          '3D m / horizontal m / yaw deg')
    for a, b in truth.outages:
        sel = np.nonzero((t >= a) & (t < b))[0]
        if len(sel) == 0:
            continue
        k = sel[-1]
        cells = '  '.join(f'{tr.label}: {e3[k]:.3f} / {eh[k]:.3f} / {da[k, 2]:+.4f}'
                          for tr, de, da, e3, eh in per_track)
        print(f'  outage {a:.0f}-{b:.0f} s, at {t[k]:.1f} s: {cells}')
    if args.errors_csv:
        with open(args.errors_csv, 'w', newline='') as fh:
            w = csv.writer(fh)
            w.writerow(['t_s', 'outage'] + [f'{label}_{q}' for label, *_ in dumps for q in (
                'e_m', 'n_m', 'u_m', 've_mps', 'vn_mps', 'vu_mps', 'roll_deg', 'pitch_deg',
                'yaw_deg')])
            for j in range(len(t)):
                row = [f'{t[j]:.3f}', int(in_outage[j])]
                for _, de, dv, da in dumps:
                    row += [f'{x:.6g}' for x in (*de[j], *dv[j], *da[j])]
                w.writerow(row)
    if args.timeline:
        print(f'timeline (every {args.timeline:.0f} s): t  then per solution 3D m, yaw deg')
        step = int(round(args.timeline * 1000))
        for j in np.nonzero(keys % step == 0)[0]:
            cells = '  '.join(f'{e3[j]:7.3f} {da[j, 2]:+8.4f}' for tr, de, da, e3, eh in per_track)
            print(f'  {t[j]:7.1f}  {cells}')
    return 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    sub = ap.add_subparsers(dest='cmd', required=True)
    ex = sub.add_parser('export', help="write KF-GINS's input files and configuration")
    ex.add_argument('bag', type=Path)
    ex.add_argument('--out', type=Path, required=True)
    ex.add_argument('--params', type=Path, action='append', required=True,
                    help='our parameter files, in replay order (later wins)')
    ex.add_argument('--increments', choices=['trapezoid', 'end-sample'], default='trapezoid',
                    help='trapezoid: as our engine (default); end-sample: each sample times '
                         'dt, stamped at its own time (a half-sample lag, for diagnosis)')
    ex.add_argument('--start-s', type=float, default=1.0,
                    help='scenario time of KF-GINS\'s start (its initial state = the truth)')
    co = sub.add_parser('compare', help='score solutions against the bag\'s truth')
    co.add_argument('bag', type=Path)
    co.add_argument('--ours', type=Path, action='append', default=[],
                    help='a `gnss_ins replay --csv` file (repeatable)')
    co.add_argument('--kfgins', type=Path, action='append', default=[],
                    help='a KF-GINS KF_GINS_Navresult.nav (repeatable)')
    co.add_argument('--from-s', type=float, default=None,
                    help='first scenario time scored (default: when every solution has started)')
    co.add_argument('--errors-csv', type=Path, default=None,
                    help='write every scored epoch\'s errors (solution - truth, ENU) here')
    co.add_argument('--timeline', type=float, default=0.0,
                    help='also print the errors every this many seconds')
    args = ap.parse_args()
    return export(args) if args.cmd == 'export' else compare(args)


if __name__ == '__main__':
    sys.exit(main())
