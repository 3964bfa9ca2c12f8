"""Fixtures of the ROS tests: one DDS domain per module, an rclpy context and client.

Every module gets its own ROS_DOMAIN_ID (reserved with ``domain_coordinator``, starting from a
pid-derived value) and ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST, exported before rclpy starts, so
DDS traffic stays on 127.0.0.0/8 and parallel runs do not see each other. Node processes inherit
both (:func:`ros_support.running_node`).
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from typing import Any

import pytest
from ros_support import RosClient, domain_selector


@pytest.fixture(scope="module")
def ros_domain() -> Iterator[int]:
    """A ROS_DOMAIN_ID reserved for this test module, exported with LOCALHOST discovery."""
    import domain_coordinator

    saved = {k: os.environ.get(k) for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")}
    with domain_coordinator.domain_id(selector=domain_selector()) as domain:
        os.environ["ROS_DOMAIN_ID"] = str(domain)
        os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
        try:
            yield domain
        finally:
            for key, value in saved.items():
                if value is None:
                    os.environ.pop(key, None)
                else:
                    os.environ[key] = value


@pytest.fixture(scope="module")
def ros_context(ros_domain: int) -> Iterator[Any]:
    """An rclpy context of this module's domain (initialised after the domain is exported)."""
    import rclpy
    from rclpy.context import Context

    context = Context()
    rclpy.init(context=context, domain_id=ros_domain)
    try:
        yield context
    finally:
        rclpy.try_shutdown(context=context)


@pytest.fixture(scope="module")
def ros_client(ros_context: Any) -> Iterator[RosClient]:
    client = RosClient(ros_context, f"hexapod_test_client_{os.getpid()}")
    try:
        yield client
    finally:
        client.close()
