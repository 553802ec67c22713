"""Summarise the covariance-diagnostic topic of a replay output bag.

    .venv/bin/python tools/noise_estimates_summary.py OUT.mcap [OUT2.mcap ...]

For every bag written by `gnss_ins replay --out`, reads `/noise_estimates`
(adaptive_gnss_ins/msg/NoiseEstimates, the types taken from this package's msg/ folder)
and prints, over the satellites used:
- the deciles of the pseudo-range and rate standard deviations the filter used (√R);
- how often the KDE test called a satellite's series Gaussian, and the AR orders in use;
- the median autocorrelation of the pseudo-range innovations at lags of 1 to 16 epochs,
  over satellites with at least 100 epochs (each series less its mean).

The last line shows how time-correlated the range errors are: a redundant-measurement
estimate, built on differences of consecutive epochs, sees √(1 − ρ(1)) of their σ.
"""

import os
import statistics
import sys
from collections import Counter
from pathlib import Path

from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore, get_types_from_msg

PACKAGE = 'adaptive_gnss_ins'
MSG_DIR = Path(__file__).resolve().parent.parent / 'msg'
TOPIC = '/noise_estimates'
LAGS_EPOCHS = (1, 2, 4, 8, 16)
MIN_SERIES_EPOCHS = 100


def typestore():
    store = get_typestore(Stores.ROS2_JAZZY)
    types = {}
    for path in sorted(MSG_DIR.glob('*.msg')):
        types.update(get_types_from_msg(path.read_text(), f'{PACKAGE}/msg/{path.stem}'))
    store.register(types)
    return store


def autocorrelation(series, lag):
    mean = statistics.fmean(series)
    centred = [x - mean for x in series]
    power = sum(x * x for x in centred)
    if power == 0.0:
        return float('nan')
    return sum(a * b for a, b in zip(centred[lag:], centred[:-lag])) / power


def deciles(values):
    if len(values) < 10:
        return [round(v, 3) for v in sorted(values)]
    return [round(v, 3) for v in statistics.quantiles(values, n=10)]


def summarise(bag, store):
    sigma_range_m, sigma_rate_mps = [], []
    gaussian, ar_orders, rejected = Counter(), Counter(), Counter()
    innovations = {}
    with AnyReader([Path(bag)], default_typestore=store) as reader:
        connections = [c for c in reader.connections if c.topic == TOPIC]
        if not connections:
            raise SystemExit(f'{bag}: no {TOPIC} topic')
        for connection, _, raw in reader.messages(connections=connections):
            message = reader.deserialize(raw, connection.msgtype)
            for sat in message.satellites:
                if not sat.used:
                    rejected[sat.rejection_reason] += 1
                    continue
                sigma_range_m.append(sat.r_pseudorange_m2 ** 0.5)
                sigma_rate_mps.append(sat.r_pseudorange_rate_m2_s2 ** 0.5)
                gaussian[bool(sat.gaussian)] += 1
                ar_orders[int(sat.ar_order)] += 1
                innovations.setdefault((sat.constellation, sat.prn), []).append(
                    sat.innovation_pseudorange_m)
    long_series = [s for s in innovations.values() if len(s) >= MIN_SERIES_EPOCHS]
    print(f'{bag}: {len(sigma_range_m)} satellite epochs used, rejected by reason '
          f'{dict(rejected)}')
    print(f'  pseudo-range sigma (m) deciles: {deciles(sigma_range_m)}')
    print(f'  rate sigma (m/s) deciles: {deciles(sigma_rate_mps)}')
    print(f'  KDE Gaussian verdicts: {dict(gaussian)}; AR orders: {dict(sorted(ar_orders.items()))}')
    if long_series:
        correlations = {lag: statistics.median(autocorrelation(s, lag) for s in long_series)
                        for lag in LAGS_EPOCHS}
        text = ', '.join(f'{lag}: {rho:.2f}' for lag, rho in correlations.items())
        print(f'  innovation autocorrelation by lag in epochs ({len(long_series)} satellites): '
              f'{text}')


def main():
    if len(sys.argv) < 2:
        raise SystemExit(__doc__)
    store = typestore()
    for bag in sys.argv[1:]:
        summarise(bag, store)


if __name__ == '__main__':
    main()
