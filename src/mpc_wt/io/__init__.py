"""Files in and out: gain tables (CSV, JSON, MAT, ROSCO's DISCON.IN), OpenFAST output files.

:mod:`.gain_tables` writes and reads a design's gain schedule in every format mpc-wt exports;
:mod:`.rosco` fills ROSCO's ``DISCON.IN`` from a tuned baseline; :mod:`.openfast_output`
reads and writes OpenFAST ``.out``/``.outb`` series with mpc-wt's channel names.
"""
from mpc_wt.io.gain_tables import FORMATS, export, load_design, read_rosco, save_design
from mpc_wt.io.openfast_output import OpenFASTSeries, read_openfast_output, write_openfast_output
from mpc_wt.io.rosco import rosco_values, write_rosco_discon

__all__ = ["FORMATS", "export", "load_design", "read_rosco", "save_design", "OpenFASTSeries",
           "read_openfast_output", "write_openfast_output", "rosco_values", "write_rosco_discon"]
