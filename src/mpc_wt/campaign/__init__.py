"""Load-case campaigns: spec (YAML), runner on Dask, results store, aggregation and reports."""
from mpc_wt.campaign.runner import ENGINES, RunSummary, run_campaign
from mpc_wt.campaign.spec import (
           DLC_DEFAULTS,
           CampaignSpec,
           Case,
           ControllerSpec,
           LoadCase,
           load_spec,
           spec_from_dict,
)
from mpc_wt.campaign.store import CampaignStore
from mpc_wt.campaign.task import case_metrics, run_case
from mpc_wt.errors import CampaignLockedError, SpecError

__all__ = ["ENGINES", "RunSummary", "run_campaign", "Case", "CampaignSpec", "ControllerSpec",
           "LoadCase", "DLC_DEFAULTS",
           "SpecError", "load_spec", "spec_from_dict", "CampaignLockedError", "CampaignStore",
           "case_metrics", "run_case"]
