"""The planner: which engine serves a scene and a request, and how the request is executed.

* :mod:`.facts`: what the planner knows of a scene (:func:`scene_facts`);
* :mod:`.request`: what a caller asks (:class:`Request`);
* :mod:`.engines`: the engines' table: what each serves, at what cost;
* :mod:`.plan`: :func:`plan`, the one pure decision;
* :mod:`.standing`: the plan known before it is made (a tiny scene's requests of x);
* :mod:`.execute`: running a plan with per-time escalation (:func:`execute`).

``ls.plan(scene, times)`` (:func:`laplace_springs.solving.plan_for`) shows the plan for a
request without evaluating anything.
"""

from __future__ import annotations

from .engines import ENGINE_NAMES, ENGINES, Cost, Engine, Refusal
from .execute import EvaluationReport, execute
from .facts import SceneFacts, scene_facts
from .plan import FAMILIES, METHODS, Plan, plan
from .request import DEFAULT_REQUEST, Request, request_for

__all__ = ["plan", "Plan", "Request", "SceneFacts", "scene_facts", "Engine",
           "ENGINES", "ENGINE_NAMES", "Cost", "Refusal", "EvaluationReport", "execute",
           "METHODS", "FAMILIES", "DEFAULT_REQUEST", "request_for"]
