"""Shared pydantic base for every case-file section: unknown keys are errors, and every float
must be finite (``.inf``, ``.nan`` and the strings ``"inf"``/``"nan"`` are refused with the key
path) unless a field allows infinity explicitly (``ExternalSource.end_time``)."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict


class StrictModel(BaseModel):
    """A case-file section: unknown keys are rejected, floats must be finite, values validated
    on assignment."""

    model_config = ConfigDict(
        extra="forbid", validate_assignment=True, frozen=False, allow_inf_nan=False
    )
