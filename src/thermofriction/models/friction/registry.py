"""The friction models, one line each (docs/architecture.md#adding-a-friction-model): the model file's ``model``
-> its class, whose description (``models/friction/base.py``: ``Description``) says the rest."""

from .coulomb import Coulomb
from .dahl import Dahl
from .elastoplastic import ElastoPlastic
from .gms import GMS
from .lugre import LuGre
from .stribeck import Stribeck

#: The friction models by the model file's name, in the order the documentation lists them.
FRICTION_MODELS = {cls.model: cls for cls in (LuGre, Coulomb, Stribeck, Dahl, ElastoPlastic, GMS)}

__all__ = ["FRICTION_MODELS"]
