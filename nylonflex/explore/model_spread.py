"""The explorer's model spread (``fidelity: spread``, docs/model.md s. 22): the read-out of
the picked design names the range of the shown variable over the cube's model variants.

:func:`spread_args` gives ``update.js`` what it needs: for each variable of the page the
indices of its ``<var>_model_lo``/``_hi`` among the page's variables (null where it has
none) and a note naming the variants. The flags of any variant (``validity_model_any``)
travel as the payload's ``validity_any`` (:func:`nylonflex.explore.page.build_payload`).
"""

from __future__ import annotations

__all__ = ["spread_args"]


def _variants(ds) -> list[str]:
    value = ds.attrs.get("model_spread", "")
    words = str(value.decode() if isinstance(value, bytes) else value)[:64 * 65].split()
    return [w[:64] for w in words[:64]]


def spread_args(ds, variables) -> dict:
    """``{"bands": [[i_lo, i_hi] or None per variable], "spreadnote": str}`` of a page
    showing ``variables`` (the payload's, in order) of cube ``ds``."""
    bands = []
    for name in variables:
        lo, hi = f"{name}_model_lo", f"{name}_model_hi"
        bands.append([variables.index(lo), variables.index(hi)]
                     if lo in variables and hi in variables else None)
    variants = _variants(ds)
    note = f"over {len(variants)} models: {', '.join(variants)}" if variants else ""
    return {"bands": bands, "spreadnote": note}
