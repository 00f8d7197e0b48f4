"""Test campaigns: many tyre tests across conditions, processed in parallel, modes tracked.

* :mod:`.spec`: the campaign file (TOML) -> :class:`Campaign`.
* :mod:`.steps`: the one adapter that knows how a test is processed.
* :mod:`.skips`: steps that cannot run on a test's data, with the reason.
* :mod:`.cache`, :mod:`.runner`: content-addressed step results; serial or Dask execution.
* :mod:`.tracking`: mode families across conditions; :mod:`.series_trend`: their trends;
  :mod:`.excitation`: the doubled modes a shaker layout drives one member of.
* :mod:`.status`: what happened to each test (step outcomes, skips, quality checks).
* :mod:`.outputs`: the result files, per-test documents and the HTML report; :mod:`.tables`:
  the tidy tables' columns and rows.
* :mod:`.virtual`: a virtual campaign with its truth.
"""

from __future__ import annotations

from .spec import Campaign, CampaignFileError, TestSpec, load_campaign

__all__ = ["Campaign", "CampaignFileError", "TestSpec", "load_campaign"]
