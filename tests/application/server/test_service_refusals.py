"""A robot calls a service wrongly (a missing argument, a service this server does not have): roslibpy's call
ends at once with the reason, as with rosbridge (a failed ``service_response``), instead of waiting for a response
that never comes (a ``status`` error is not an answer to the call)."""

from __future__ import annotations

import pytest
import roslibpy

WAIT = 30.0


def refusal(ros: roslibpy.Ros, name: str, service_type: str, arguments: dict[str, object]) -> str:
    """The error a call of ``name`` with ``arguments`` ends with."""
    service = roslibpy.Service(ros, name, service_type)
    with pytest.raises(roslibpy.core.ServiceException) as refused:
        service.call(roslibpy.ServiceRequest(arguments), timeout=WAIT)
    return str(refused.value)


def test_a_plan_call_without_its_query_is_refused_with_the_argument_named(ros: roslibpy.Ros) -> None:
    reason = refusal(ros, "/robokudo/plan", "robokudo_msgs/srv/Plan", {"qery": "find milk"})
    assert "needs the argument 'query'" in reason


def test_an_ontology_call_without_an_action_is_refused_with_the_argument_named(ros: roslibpy.Ros) -> None:
    reason = refusal(ros, "/robokudo/ontology", "robokudo_msgs/srv/Ontology", {})
    assert "needs the argument 'action'" in reason


def test_a_call_of_a_service_the_server_lacks_is_refused_with_the_services_it_has(ros: roslibpy.Ros) -> None:
    reason = refusal(ros, "/robokudo/teleport", "std_srvs/srv/Trigger", {})
    assert "unknown service '/robokudo/teleport'" in reason and "/robokudo/plan" in reason
