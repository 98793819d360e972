#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Integrates the resonator's free-decay ODE (physics.md eq. 1) with SciPy's
solve_ivp (DOP853, rtol 1e-10) and compares it with a trajectory written by
the sim_target benchmark: prints the wall-time ratio and the maximum
difference. Run by bench_sim_target; usable alone:

  scipy_compare.py TRAJ.csv
TRAJ.csv: '# key=value' lines (f_hz, q, dmu, th_mu_rad, split_hz, th_w_rad,
angular_gain, rate_rad_s, wall_s) then rows 't_s,x_v,y_v,vx,vy'.
"""
import math
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp


def main(path):
    meta = {}
    rows = []
    with open(path) as f:
        for line in f:
            if line.startswith('#'):
                k, v = line[1:].strip().split('=')
                meta[k.strip()] = float(v)
            elif line.strip() and not line.startswith('t_s'):
                rows.append([float(c) for c in line.split(',')])
    data = np.array(rows)
    t = data[:, 0]
    w = 2 * math.pi * meta['f_hz']
    nu = math.pi * meta['f_hz'] / meta['q']
    dmu = meta['dmu']
    c4mu, s4mu = math.cos(4 * meta['th_mu_rad']), math.sin(4 * meta['th_mu_rad'])
    dw2 = 2 * w * math.pi * meta['split_hz']
    c4w, s4w = math.cos(4 * meta['th_w_rad']), math.sin(4 * meta['th_w_rad'])
    gk = 2 * meta['rate_rad_s'] * meta['angular_gain']
    d11, d12, d22 = 2 * nu * (1 + dmu * c4mu), 2 * nu * dmu * s4mu, 2 * nu * (1 - dmu * c4mu)
    k11, k12, k22 = w * w + dw2 * c4w, dw2 * s4w, w * w - dw2 * c4w

    def rhs(_t, u):
        x, y, vx, vy = u
        ax = -(d11 * vx + d12 * vy - gk * vy + k11 * x + k12 * y)
        ay = -(d22 * vy + d12 * vx + gk * vx + k22 * y + k12 * x)
        return [vx, vy, ax, ay]

    start = time.perf_counter()
    start_cpu = time.process_time()
    sol = solve_ivp(rhs, (t[0], t[-1]), data[0, 1:5], method='DOP853', rtol=1e-10,
                    atol=1e-12 * max(1.0, w), t_eval=t)
    wall = time.perf_counter() - start
    cpu = time.process_time() - start_cpu
    if not sol.success:
        print('scipy: solve_ivp failed:', sol.message)
        return 1
    dx = np.max(np.abs(sol.y[0] - data[:, 1]))
    dy = np.max(np.abs(sol.y[1] - data[:, 2]))
    amp = np.max(np.abs(data[:, 1:3]))
    print(f'scipy DOP853 rtol 1e-10: {t[-1] - t[0]:.3f} s of free decay, {sol.nfev} RHS calls, '
          f'wall {wall:.3f} s, CPU {cpu:.3f} s')
    print(f'sim_target full rate:    wall {meta["wall_s"]:.6f} s, CPU {meta["cpu_s"]:.6f} s')
    print(f'wall-time ratio scipy/sim = {wall / meta["wall_s"]:.0f}, '
          f'CPU-time ratio = {cpu / max(meta["cpu_s"], 1e-6):.0f}')
    print(f'max |x_sim - x_scipy| = {dx:.3e} V, max |y_sim - y_scipy| = {dy:.3e} V '
          f'(amplitude {amp:.3f} V, relative {max(dx, dy) / amp:.2e})')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1]))
