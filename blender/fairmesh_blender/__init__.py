"""fairmesh inside Blender: Fair Mesh (``object.fairmesh_fair``) removes noise and unwanted
detail from meshes without shrinking them, with the ``fairmesh`` Python package.

The add-on's files:

- ``operator.py``: the operator, its options and the menus' entry;
- ``mesh_data.py``: a mesh read into arrays and the result written back (foreach_get/set);
- ``work.py``: the fairing on arrays, with no Blender in it, and the hierarchies kept between
  redos.

Installed from the zip as a classic add-on, the ``fairmesh`` package comes from the ``vendor``
folder beside this file (the wheel unpacked); as a Blender 4.2+ extension, Blender installs the
wheel the manifest lists and the package is found as it is.
"""

import os
import sys

bl_info = {
    "name": "fairmesh",
    "author": "The fairmesh authors",
    "version": (0, 1, 0),
    "blender": (3, 3, 0),
    "location": "View3D > Object > Fair Mesh; Edit mode: Mesh > Fair Mesh; F3: Fair Mesh",
    "description": "Remove noise and unwanted detail from meshes without shrinking them "
                   "(constrained fairing)",
    "category": "Mesh",
}

_vendor = os.path.join(os.path.dirname(os.path.abspath(__file__)), "vendor")
_extension = __package__.startswith("bl_ext.")  # Blender 4.2+ installed the wheel itself
if not _extension and os.path.isdir(_vendor) and _vendor not in sys.path:
    # The classic add-on carries the package; put its copy first so that this add-on's
    # version is the one used.
    sys.path.insert(0, _vendor)

import bpy  # noqa: E402

from . import operator  # noqa: E402

_MENUS = ("VIEW3D_MT_object", "VIEW3D_MT_edit_mesh")


def register():
    bpy.utils.register_class(operator.OBJECT_OT_fairmesh_fair)
    for menu in _MENUS:
        getattr(bpy.types, menu).append(operator.menu_entry)


def unregister():
    for menu in _MENUS:
        getattr(bpy.types, menu).remove(operator.menu_entry)
    bpy.utils.unregister_class(operator.OBJECT_OT_fairmesh_fair)
    operator.work.kept.clear()
