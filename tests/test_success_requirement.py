"""A campaign's success-probability requirement (campaign.success_requirement): the runs that show
it against the exact binomial bounds, the three verdicts with their figures, the report's row and
``drake-entry campaign --until-confident`` running in batches until the verdict is decided."""
import json
import os

import pytest
from scipy import stats

from drake_entry.campaign.statistics import success_lower_bound, success_upper_bound
from drake_entry.campaign.success_requirement import runs_to_show, success_verdict
from drake_entry.cli import main
from drake_entry.errors import ScenarioError
from drake_entry.scenario import load_scenario


@pytest.mark.parametrize("failures, probability, confidence, expected", [
    (0, 0.9973, 0.90, 852),  # ln(0.1) / ln(0.9973) = 851.6
    (0, 0.99, 0.90, 230),
    (0, 0.95, 0.95, 59),
    (2, 0.99, 0.90, 531),
])
def test_the_runs_that_show_a_probability_are_the_fewest_whose_lower_bound_reaches_it(failures, probability,
                                                                                      confidence, expected):
    n = runs_to_show(failures, probability, confidence)
    assert n == expected
    assert success_lower_bound(n - failures, n, confidence) >= probability
    assert success_lower_bound(n - 1 - failures, n - 1, confidence) < probability


def test_the_upper_bound_is_the_failures_lower_bound_complemented():
    assert success_upper_bound(0, 100, 0.9) == pytest.approx(1.0 - 0.1 ** (1 / 100), rel=1e-12)
    assert success_upper_bound(100, 100, 0.9) == 1.0
    assert success_upper_bound(90, 100, 0.9) == pytest.approx(stats.beta.ppf(0.9, 91, 10), rel=1e-10)
    for k in (1, 37, 99):
        assert success_upper_bound(k, 100, 0.95) == pytest.approx(1.0 - success_lower_bound(100 - k, 100, 0.95))
        assert success_lower_bound(k, 100, 0.95) < k / 100 < success_upper_bound(k, 100, 0.95)


def test_the_three_verdicts_say_what_was_shown_with_their_figures():
    shown = success_verdict(852, 852, 0.9973, 0.9)
    assert shown.status == "PASS" and shown.lower >= 0.9973 and shown.text().startswith("PASS: 852 of 852")
    open_ = success_verdict(100, 100, 0.9973, 0.9)
    assert open_.status == "OPEN" and open_.more_runs == 752 and open_.lower == pytest.approx(0.97724, abs=1e-5)
    assert "752 more runs, every one successful, would show it" in open_.text()
    assert success_verdict(99, 100, 0.9973, 0.9).more_runs == runs_to_show(1, 0.9973, 0.9) - 100
    failed = success_verdict(90, 100, 0.9973, 0.9)
    assert failed.status == "FAIL" and failed.more_runs is None
    assert "below 99.73 % (upper bound 93.689 %): shown not met" in failed.text()


@pytest.mark.parametrize("probability, confidence, words", [
    (1.0, 0.9, "success_requirement.probability = 1.0: allowed in (0, 1)"),
    (0.0, 0.9, "success_requirement.probability = 0.0: allowed in (0, 1)"),
    (0.99, 0.5, "success_requirement.confidence = 0.5: allowed in (0.5, 1)"),
])
def test_a_bad_requirement_is_named(probability, confidence, words):
    with pytest.raises(ScenarioError, match=words.replace("(", r"\(").replace(")", r"\)")):
        success_verdict(10, 10, probability, confidence)
    s = load_scenario("horus2b")
    s.success_requirement.probability, s.success_requirement.confidence = probability, confidence
    with pytest.raises(ScenarioError, match=words.replace("(", r"\(").replace(")", r"\)")):
        s.validate()


def test_until_confident_runs_in_batches_until_the_requirement_is_shown(tmp_path):
    """50 % at 90 % needs 4 successes of 4 (0.5^4 <= 0.1 < 0.5^3): 2 runs first (OPEN, lower bound
    31.6 %), then the 2 that would show it; the report's requirement row and summary say PASS."""
    out = str(tmp_path / "c")
    code = main(["campaign", "horus2b", "--runs", "2", "--until-confident", "--workers", "1", "--trajectory-step",
                 "0", "--set", "success_requirement.probability=0.5", "--out", out])
    summary = json.load(open(os.path.join(out, "summary.json")))
    assert code == 0 and summary["samples"] == 4 and summary["successful"] == 4
    required = summary["success_requirement"]
    assert required["status"] == "PASS" and required["lower"] == pytest.approx(0.1 ** 0.25)
    report = open(os.path.join(out, "report.md")).read()
    assert "| success probability | >= 50 % at 90 % confidence |" in report and "PASS: 4 of 4 successful" in report


def test_until_confident_needs_a_stated_requirement(tmp_path, capsys):
    assert main(["campaign", "horus2b", "--runs", "2", "--until-confident", "--set", "success_requirement.probability=null",
                 "--out", str(tmp_path / "c")]) != 0
    assert ("horus2b: running until confident needs the scenario's success_requirement.probability (e.g. 0.9973"
            in capsys.readouterr().err)
    assert not os.path.exists(tmp_path / "c")  # refused before any sample


def test_a_packaged_campaign_too_small_to_judge_its_3_sigma_requirement_says_so_and_exits_zero(tmp_path, capsys):
    """horus2b requires 99.73 % at 90 % (the project's 3-sigma requirement, its source named): 2
    successful runs leave it OPEN (850 more successful runs would show it: 852 in all), which is
    not a failure (exit 0); the report's requirement row names the source."""
    out = str(tmp_path / "c")
    assert main(["campaign", "horus2b", "--runs", "2", "--workers", "1", "--trajectory-step", "0", "--out", out]) == 0
    err = capsys.readouterr().err
    assert "the success requirement is not shown: OPEN: 2 of 2 successful" in err and "850 more runs" in err
    required = json.load(open(os.path.join(out, "summary.json")))["success_requirement"]
    assert required["status"] == "OPEN" and required["more_runs"] == 850
    assert "Hanson & Beard, NASA/TP-2010-216447" in open(os.path.join(out, "report.md")).read()
