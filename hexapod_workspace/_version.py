"""The package's version: the one definition read by ``setup.py`` and ``hexapod_workspace``.

The two ``package.xml`` files (ROS needs a literal there) are checked against it by
``test/test_facts.py``.
"""

__version__ = "0.1.0"
