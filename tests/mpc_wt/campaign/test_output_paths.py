"""Every name a spec sets that becomes part of a file or folder name is refused when it could
reach outside the output folder: the campaign's and the tuning's name, a controller's name,
a load case's ``dlc``, a controller's ``dlcs`` and the tuning reference's name. A case id that
is not one file name is refused where the case's file is named, whatever made it."""
from __future__ import annotations

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mpc_wt.campaign import SpecError, spec_from_dict
from mpc_wt.campaign.task import case_file
from mpc_wt.tuning.spec import tune_spec_from_dict

BASE = {"name": "t", "duration": 20, "transient": 5, "winds": [14], "seeds": 1,
        "controllers": ["baseline"]}
TRAVERSALS = ["../outside", "1.2/../../../../outside", "/etc/x", "..", ".hidden", "a\\..\\b",
              "a b/c", "x\x00y", "é", "a" * 101, ""]


def _load_case(dlc):
    return {"load_cases": [{"dlc": dlc, "condition": "ntm", "winds": [18], "seeds": 1}]}


@pytest.mark.parametrize("bad", TRAVERSALS)
@pytest.mark.parametrize("where, make", [
    ("name", lambda v: {"name": v}),
    ("controllers[0].name", lambda v: {"controllers": [{"name": v, "controller": "baseline"}]}),
    ("controllers[0].name", lambda v: {"controllers": [v]}),
    ("load_cases[0].dlc", _load_case),
    ("controllers[0].dlcs[0]", lambda v: {**_load_case("1.2"), "controllers": [
        {"name": "b", "controller": "baseline", "dlcs": [v]}]}),
])
def test_campaign_names_cannot_leave_the_output_folder(bad, where, make) -> None:
    with pytest.raises(SpecError) as err:
        spec_from_dict({**BASE, **make(bad)})
    msg = str(err.value)
    assert where in msg or (bad == "" and "name" in msg), msg
    if bad:
        assert "letters, digits and - _ . +" in msg or "must" in msg


def _tune_raw(**over):
    raw = {"name": "t", "duration": 40, "transient": 10, "turbulence": "A", "winds": [18],
           "seeds": [1], "holdout_seeds": [2], "channels": {"tower_base_fa_moment": 4},
           "controller": {"controller": "baseline"},
           "reference": {"name": "ref", "controller": "baseline"},
           "parameters": {"omega_n_rad_s": {"low": 0.3, "high": 1.0}},
           "objective": [{"metric": "del:tower_base_fa_moment", "weight": 1}], "trials": 3}
    raw.update(over)
    return raw


@pytest.mark.parametrize("bad", [b for b in TRAVERSALS if b])
def test_tuning_names_cannot_leave_the_output_folder(bad) -> None:
    with pytest.raises(SpecError, match=r"name: must be a name of letters"):
        tune_spec_from_dict(_tune_raw(name=bad))
    with pytest.raises(SpecError, match=r"reference.name: must be a name of letters"):
        tune_spec_from_dict(_tune_raw(reference={"name": bad, "controller": "baseline"}))


def test_the_names_of_real_specs_still_pass() -> None:
    spec = spec_from_dict({**BASE, "name": "dlc12-baseline_v2.1+ipc",
                           **_load_case("1.2"), "controllers": ["baseline", "derate80+ibc"]})
    ids = [c.case_id for c in spec.cases()]
    assert ids and all(case_file(i) == f"cases/{i}.nc" for i in ids)


@settings(max_examples=200, deadline=None)
@given(st.text(min_size=1, max_size=40))
def test_a_case_file_is_one_file_under_cases(case_id: str) -> None:
    """Any case id: either its file is ``cases/<one name>.nc`` with no separator or leading
    dot in the name, or it is refused."""
    try:
        rel = case_file(case_id)
    except ValueError as err:
        assert "is not a file name" in str(err)
        return
    name = rel[len("cases/"):-len(".nc")]
    assert rel.startswith("cases/") and name == case_id
    assert "/" not in name and "\\" not in name and not name.startswith(".")
