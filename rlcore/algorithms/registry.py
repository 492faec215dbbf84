"""The one registry of algorithm families: everything that needs a family's config, agent, training
loop, saved policy or export asks here, by the family's ``kind``. Adding a family is one folder
(``rlcore/algorithms/<kind>/``) and one line below (``docs/developer/adding-an-algorithm.md``).
"""
from __future__ import annotations

from rlcore.algorithms import a2c, dqn, ppo, sac
from rlcore.algorithms.family import Family
from rlcore.errors import UserError

FAMILIES: dict[str, Family] = {family.kind: family for family in (dqn.FAMILY, a2c.FAMILY, ppo.FAMILY, sac.FAMILY)}


def family(kind: str) -> Family:
    """The family of ``kind``; a kind the registry does not know is one clear line, never another's."""
    try:
        return FAMILIES[kind]
    except KeyError:
        raise UserError(f"no algorithm family {kind!r} in this package (known: {', '.join(FAMILIES)}); "
                        "a model or run of it was made by a version of the package that had it") from None


def register(new: Family) -> None:
    """Add a family (a plug-in's, or a test's toy one); a kind already taken is refused."""
    if new.kind in FAMILIES:
        raise UserError(f"an algorithm family {new.kind!r} is registered already")
    FAMILIES[new.kind] = new


def unregister(kind: str) -> None:
    FAMILIES.pop(kind, None)
