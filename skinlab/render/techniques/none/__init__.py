"""Technique "none": plain Burley diffuse everywhere, no subsurface scattering (the ledger's
lower bound: what skin looks like without it)."""

from __future__ import annotations

from dataclasses import dataclass

from skinlab.render.options import TechniqueSettings
from skinlab.render.technique import LedgerStyle, LedgerSweep, PlanContext, Technique, TechniquePlan


@dataclass(frozen=True)
class NoneSettings(TechniqueSettings):
    technique = "none"


class NoneTechnique(Technique[NoneSettings]):
    name = "none"
    description = "no subsurface scattering: plain Burley diffuse (the lower bound)"
    settings_type = NoneSettings
    ledger = LedgerStyle("X", "tab:red", sweep={"tiny": LedgerSweep()})  # tiny too: the baselines
    scatters = False

    def plan(self, ctx: PlanContext) -> TechniquePlan:
        ctx.plan.skipped.append(("subsurface scattering", "technique is none: plain diffuse"))
        return TechniquePlan()


TECHNIQUE = NoneTechnique()
