"""Load-case campaigns: spec (YAML), runner on Dask, results store, aggregation and reports."""
from .runner import ENGINES, RunSummary, run_campaign
from .spec import (DLC_DEFAULTS, Case, CampaignSpec, ControllerSpec, LoadCase, SpecError,
                   load_spec, spec_from_dict)
from .store import CampaignLockedError, CampaignStore
from .task import case_metrics, run_case

__all__ = ["ENGINES", "RunSummary", "run_campaign", "Case", "CampaignSpec", "ControllerSpec",
           "LoadCase", "DLC_DEFAULTS",
           "SpecError", "load_spec", "spec_from_dict", "CampaignLockedError", "CampaignStore",
           "case_metrics", "run_case"]
