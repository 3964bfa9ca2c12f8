"""Fixtures of the ROS tests: one DDS domain per module, an rclpy context and client.

Every module gets its own ROS_DOMAIN_ID (reserved with ``domain_coordinator``, starting from a
pid-derived value) and ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST, exported before rclpy starts, so
DDS traffic stays on 127.0.0.0/8 and parallel runs do not see each other. Node processes inherit
both (:func:`ros_support.running_node`).
"""

from __future__ import annotations

import os
import threading
from collections.abc import Iterator
from typing import Any

import pytest
from ros_support import RosClient, domain_selector, running_node

from hexapod_workspace import Manipulator
from hexapod_workspace.core.evaluation.loading import load_manipulator


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


#: The longest a module's teardown waits for a node's background kernel warm-up (s).
WARM_UP_JOIN_TIMEOUT = 900.0


@pytest.fixture(scope="module", autouse=True)
def kernel_warm_up_finished() -> Iterator[None]:
    """At the end of a module, wait for the background warm-up of the nodes it built in this
    process (``WorkspaceNode.warm_up``'s "kernel-warm-up" thread, which compiles every kernel
    of the model into the source tree's cache for minutes), so that the next module's tests run
    without numba compiling beside them in another thread. A CI run crashed with SIGSEGV in
    the garbage collector, in the module after the in-process nodes; compilation in a second
    thread is the suspect (not proven), and this keeps it out of the other modules' way."""
    yield
    for thread in threading.enumerate():
        if thread.name == "kernel-warm-up":
            thread.join(timeout=WARM_UP_JOIN_TIMEOUT)
            assert not thread.is_alive(), (
                f"kernel warm-up still running after {WARM_UP_JOIN_TIMEOUT} s"
            )


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


@pytest.fixture(scope="module")
def workspace_node(ros_domain: int, tmp_path_factory: pytest.TempPathFactory, request) -> Iterator:
    """The module's workspace_node process, started with the module's ``NODE_PARAMS``
    (dotted-name overrides of the example parameters file)."""
    overrides = getattr(request.module, "NODE_PARAMS", {})
    with running_node(tmp_path_factory.mktemp("workspace_node"), overrides) as node:
        yield node


@pytest.fixture(scope="module")
def model(workspace_node) -> Manipulator:
    """The manipulator the node was started with, built by the core from the same file."""
    return load_manipulator(workspace_node.params_path)


@pytest.fixture(scope="module")
def client(ros_client: RosClient, workspace_node) -> RosClient:
    """``ros_client`` once the module's node serves (its check_poses service is discovered)."""
    from hexapod_workspace_msgs.srv import CheckPoses

    ros_client.client(CheckPoses, "/hexapod_workspace/check_poses")
    return ros_client
