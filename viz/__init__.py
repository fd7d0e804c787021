"""Visualisation: trajectories as self-contained browser animations, and the review page.

* ``geometry``  — the URDF's visuals through Pinocchio's visual model, posed by forward kinematics;
* ``skeleton``  — joints, rods and centres of mass for the bodies a description gives no visuals;
* ``recorder``  — meshcat commands recorded in memory and written as one HTML file (no server);
* ``animation`` — frames, camera, tip trace: ``render_html(Trajectory)``;
* ``plots``     — energy and work-balance figures (matplotlib, SVG);
* ``review``    — the review page ``index.html``;
* ``browser``   — headless Chromium over the DevTools pipe, for screenshots and tests.

Internal (``__all__`` is empty): docs/reference/api.md lists what is public.
"""

import warnings

with warnings.catch_warnings():  # meshcat's server module imports pyzmq's deprecated ioloop shim
    warnings.simplefilter("ignore", DeprecationWarning)
    import meshcat  # noqa: F401

__all__: list[str] = []
