"""``mocycle studio``: a local web application to review loops on a library of takes and to author new motion
on the spatial-keyframe plane (thesis 002, chapter 6); ``mocycle report``: the same viewer in one HTML file.

A front end: the JSON API calls :mod:`mocycle.tasks` (``info``, ``loop``, ``project``, ``author``) and
nothing deeper; the page (``static/``, plain ES modules, three.js |THREE| vendored) draws the skeleton and,
for the continuous interactions (scrubbing, hovering and drawing on the plane), evaluates poses itself
from the arrays the server sends.  Needs the ``studio`` extra (starlette, uvicorn).
"""

THREE_VERSION = "0.179.1"
