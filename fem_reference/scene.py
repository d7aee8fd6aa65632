"""The scene on the FEM command line: its options and the Strip and LoadingProtocol they give."""
from __future__ import annotations

import argparse


def add_scene_options(p: argparse.ArgumentParser) -> None:
    """The scene options shared by `run`, `convergence` and `gold`."""
    p.add_argument("--width-ratio", type=float, required=True, help="W/L in (0, 1]")
    p.add_argument("--compression-ratio", type=float, required=True, help="dL/L in [0.001, 0.9]")
    p.add_argument("--shear-ratio", type=float, default=None, help="largest dW/L (default dW_max/L, Eq. B.1)")
    p.add_argument("--slenderness", type=float, default=None, help="L/b in [10, 1e5] (default b = 0.127 mm)")
    p.add_argument("--poisson-ratio", type=float, default=0.0, help="nu in [0, 0.5) (default 0)")
    p.add_argument("--compression-steps", type=int, default=40, help="recorded compression steps, 1..5000 (default 40)")
    p.add_argument("--shear-steps", type=int, default=120, help="recorded shear steps, 1..5000 (default 120)")
    p.add_argument("--shear-sign", type=int, default=1, choices=(1, -1))


def scene_from_args(args):
    """Strip and LoadingProtocol of the scene options (ddg validates them: one-line InputError)."""
    from ddg.geometry.strip import LoadingProtocol, Strip
    from ddg.limits import check_steps

    check_steps("--compression-steps", args.compression_steps)
    check_steps("--shear-steps", args.shear_steps)
    strip = Strip.from_ratios(args.width_ratio, args.compression_ratio, args.slenderness,
                              poisson_ratio=args.poisson_ratio)
    protocol = LoadingProtocol(args.compression_ratio, args.shear_ratio, args.compression_steps,
                               args.shear_steps, args.shear_sign)
    protocol.resolved_shear_ratio(strip)
    return strip, protocol
