"""The reference driver in a VUT's place: the configuration of a counterfactual replay.

Used by the preventability labels (:mod:`sumo_ayss.scenarios.preventability`) and by the
envs that label crashes online (:mod:`sumo_ayss.envs.lead_and_cut_in`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from typing import Any

from sumo_ayss.config import EnvConfig
from sumo_ayss.util.errors import ConfigError
from sumo_ayss.vuts.reference_types import REFERENCE_VUTS
from sumo_ayss.vuts.vtype_params import CONTROLLED_BODY_PARAMS

__all__ = ["reference_config"]


def reference_config(
    config: EnvConfig,
    reference: str,
    *,
    own_body: bool = False,
    params: Mapping[str, Any] | None = None,
) -> EnvConfig:
    """``config`` with the reference driver ``reference`` in the VUT's place and body.

    The reference's catalog entry (:data:`~sumo_ayss.vuts.reference_types.REFERENCE_VUTS`) keeps its
    controller; its body (length, width, ...) is the VUT's where the VUT gives one, so that
    the replay's geometry is the original's (``own_body``: the reference's own 5 m x 1.8 m
    body instead, for its own row in cross-play). Entered into the catalog under
    ``reference``.
    """
    if reference not in REFERENCE_VUTS:
        raise ConfigError(
            f"reference driver must be one of {sorted(REFERENCE_VUTS)}, got {reference!r}"
        )
    ref = REFERENCE_VUTS[reference]
    body = {k: v for k, v in config.vut_type.params.items() if k in CONTROLLED_BODY_PARAMS}
    if own_body:
        body = {}
    vt = dataclasses.replace(ref, params={**ref.params, **body})
    if params and vt.controller is not None:
        controller = dataclasses.replace(vt.controller, params={**vt.controller.params, **params})
        vt = dataclasses.replace(vt, controller=controller)
    vuts = {**config.vuts, reference: vt}
    return dataclasses.replace(config, vuts=vuts, vut=reference)
