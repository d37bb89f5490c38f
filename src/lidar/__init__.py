"""Turbulent wind fields and a hub-mounted continuous-wave LIDAR (issue 4).

This package imports neither ``linearize`` nor ``mpc_wt``.
"""
__all__: list[str] = []
