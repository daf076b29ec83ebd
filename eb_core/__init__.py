"""EmbodiedBench core: hook specs, registries, typed models, the planner pipeline, runner and metrics.

The core never imports a simulator or a model SDK; worlds and model backends are plugins.
"""

from eb_core.env import (
    Action,
    ActionSpace,
    DiscreteActionSpace,
    Env,
    ObjectInfo,
    Observation,
    PlanItemError,
    PromptParts,
    StepResult,
    Task,
    VectorActionSpace,
)
from eb_core.hookspecs import hookimpl
from eb_core.model import (
    EpisodeContext,
    ImagePart,
    Message,
    ModelBackend,
    ModelBudgetExceeded,
    ModelError,
    ModelFatalError,
    ModelRequest,
    ModelResponse,
    ModelTransientError,
    TextPart,
    Usage,
)
from eb_core.plugins import PluginError, Registry, get_plugin_manager
from eb_core.specs import AugmenterSpec, EnvSpec, MetricSpec, ModelBackendSpec, PlannerSpec

__version__ = "0.1.0"

__all__ = [
    "Action",
    "ActionSpace",
    "AugmenterSpec",
    "DiscreteActionSpace",
    "Env",
    "EnvSpec",
    "EpisodeContext",
    "ImagePart",
    "Message",
    "MetricSpec",
    "ModelBackend",
    "ModelBackendSpec",
    "ModelBudgetExceeded",
    "ModelError",
    "ModelFatalError",
    "ModelRequest",
    "ModelResponse",
    "ModelTransientError",
    "ObjectInfo",
    "Observation",
    "PlanItemError",
    "PlannerSpec",
    "PluginError",
    "PromptParts",
    "Registry",
    "StepResult",
    "Task",
    "TextPart",
    "Usage",
    "VectorActionSpace",
    "get_plugin_manager",
    "hookimpl",
]
