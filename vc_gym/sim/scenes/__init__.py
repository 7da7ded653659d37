"""The simulated scenes: a registry of named scene builders, five of them built in.

Built-in scenes (:data:`SCENES`): the paper's robot lab, its "other environments"
(section 5), and a plain house beyond the paper:

* ``"robolab"``: the UvA Robolab of the paper, a 7 x 7 m room with a 6 x 4 m green
  carpet field, RoboCup goals, tables with computers, windows, shelves, boards and
  posters (:mod:`vc_gym.sim.scenes.robolab`);
* ``"office"``: desks with monitors, tall shelves with binders, a whiteboard, windows
  with blinds, filing cabinets and plants (:mod:`vc_gym.sim.scenes.office`);
* ``"home"``: a living room in warm colours with a sofa, bookshelf, TV, rug and
  paintings (:mod:`vc_gym.sim.scenes.home`);
* ``"outdoor_field"``: a grass pitch with advertising boards, floodlights, a
  grandstand, trees and buildings inside a sky cylinder
  (:mod:`vc_gym.sim.scenes.outdoor_field`);
* ``"plain_house"``: a living room as plain as a real house, 5.5 x 4.5 m: off-white
  walls, white ceiling, light wooden floor, a grey sofa, a white wardrobe, a table with
  two chairs, a low shelf, two bright windows, a door and two small prints, no posters
  (:mod:`vc_gym.sim.scenes.plain_house`): the other rooms are much busier than real
  houses, which flatters an appearance-based compass.

Every built-in scene is *closed* (walls and ceiling, or the sky cylinder and its lid), so
every camera ray hits something and :attr:`Scene.background_rgb` is ``None``.
``build_scene(bc, name, rng, randomize=False)`` builds the canonical scene for a name
(the same for any ``rng``); ``randomize=True`` draws wall and floor colours, poster
selection and placement, furniture placement, pictures and the light direction from
``rng``.

Your own scene
--------------
Register a builder function under a new name with :func:`register_scene`; from then on
the name works wherever a built-in scene name does (``gym.make(..., scene=name)`` for
``vc_gym/AiboRoom-v0`` and ``vc_gym/LearnThenHome-v0``, :func:`build_scene`). The builder
gets a :class:`Builder`, creates the scene's bodies through it and returns
``(room_bounds, field_bounds, light_direction)``. The toolkit, exported here too:

* :mod:`~vc_gym.sim.scenes.builder`: :class:`Builder` makes textured quads
  (:meth:`Builder.mesh`), furniture (:meth:`Builder.solid`) and invisible walls
  (:meth:`Builder.fence`); its :attr:`Builder.choices` (a :class:`Draw`, in
  :mod:`~vc_gym.sim.scenes.choices`) gives each layout choice its canonical value, or a
  random one when the scene is built with ``randomize=True``;
* :mod:`~vc_gym.sim.scenes.parts`: furniture shapes :class:`Part` (:func:`box`,
  :func:`cyl`, :func:`ball`);
* :mod:`~vc_gym.sim.scenes.rooms`: a :class:`Room` of four :class:`Wall` canvases,
  built with its floor and ceiling;
* :mod:`~vc_gym.sim.scenes.scene`: :class:`Scene` (a built scene) and
  :class:`SceneLayout` (what a builder returns);
* :mod:`vc_gym.sim.scenes.furniture`: doors, windows, pictures, desks, shelves...

Textures are painted on a :class:`vc_gym.sim.textures.Canvas`. A small box room with
four coloured walls and a poster::

    import gymnasium as gym

    import vc_gym  # registers the envs
    from vc_gym.sim import textures
    from vc_gym.sim.scenes import Room, SceneLayout, register_scene
    from vc_gym.sim.scenes.furniture import ceiling_texture, sun


    @register_scene("my_room", canonical_seed=1)
    def my_room(b):
        bounds, field = (-2.5, 2.5, -2.0, 2.0), (-1.5, 1.5, -1.2, 1.2)  # xmin, xmax, ymin, ymax
        paint = {"E": (200, 40, 40), "N": (40, 160, 60), "W": (40, 70, 200), "S": (230, 200, 40)}
        # b.choices.color gives the paint itself, or a nearby colour when randomize=True
        room = Room(b, bounds, 2.5, {side: b.choices.color(rgb) for side, rgb in paint.items()})
        poster = textures.procedural_poster(b.rng, (120, 90), "blocks")
        north = room.walls["N"]  # u runs left to right seen from inside, z up
        north.canvas.framed(1.5, 2.4, 0.5, 1.7, poster, (25, 25, 25), 0.04)
        north.take(1.5, 2.4, 0.5, 1.7)
        floor = textures.Canvas(5.0, 4.0, 50.0, (120, 110, 100))  # x by y metres, 50 px/m
        floor.mottle(b.rng, 0.05, 0.5)
        room.build(floor.image(), ceiling_texture(b, bounds, panels=False))
        return SceneLayout(bounds, field, sun(b, (0.3, -0.4, 0.85)))


    env = gym.make("vc_gym/AiboRoom-v0", scene="my_room")
    obs, info = env.reset(seed=0)

Take every random draw from ``b.rng`` or ``b.choices`` (never ``np.random``): the canonical
scene is then built from ``canonical_seed`` and is always the same, and a randomised one
is the same for the same seed. Keep ``field_bounds`` (where the robot is placed and
kidnapped to) at least 0.2 m from walls and furniture; ``vc_gym/LearnThenHome-v0`` puts
home at the origin and learns at spots 1 m from it, so keep those on the field too. Use
``overwrite=True`` to replace a registration and :func:`unregister_scene` to remove one
(e.g. in a test fixture).

**Worker processes.** The registry lives in each Python process. A scene registered in a
script or notebook is unknown in worker processes that start a fresh interpreter
(``AsyncVectorEnv`` or stable-baselines3's ``SubprocVecEnv`` with the ``spawn`` or
``forkserver`` start method; only ``fork`` copies the registry), and the env there fails
with ``unknown scene``. Put the builder in an importable module (not in ``__main__``) and
import that module where the worker creates its env::

    def make_env():
        import my_scenes  # registers "my_room" in this process

        return gym.make("vc_gym/AiboRoom-v0", scene="my_room")

    envs = gym.vector.AsyncVectorEnv([make_env, make_env])

``functools.partial(gym.make, "my_scenes:vc_gym/AiboRoom-v0", scene="my_room")`` works too
(Gymnasium imports the module before the ``:``), but ``gym.make_vec`` with such an id
does not import it in its workers.
"""

import importlib

from vc_gym.sim.scenes.builder import Builder, Quad
from vc_gym.sim.scenes.choices import Draw
from vc_gym.sim.scenes.parts import RGB, Part, ball, box, cyl
from vc_gym.sim.scenes.registry import (
    build_scene,
    check_scene_name,
    register_scene,
    scene_names,
    unregister_scene,
)
from vc_gym.sim.scenes.rooms import FLOOR_PPM, WALL_PPM, Room, Wall
from vc_gym.sim.scenes.scene import Scene, SceneLayout

#: Names of the BUILT-IN scenes, kept for backwards compatibility. Scenes registered
#: later are not in it: use :func:`scene_names` for every registered scene.
SCENES: tuple[str, ...] = ("robolab", "office", "home", "outdoor_field", "plain_house")

# each built-in scene's module registers it on import; in this order, so that
# scene_names() and error messages list them as SCENES does
for _module in SCENES:
    importlib.import_module(f"vc_gym.sim.scenes.{_module}")
del _module

__all__ = [
    "FLOOR_PPM",
    "RGB",
    "SCENES",
    "WALL_PPM",
    "Builder",
    "Draw",
    "Part",
    "Quad",
    "Room",
    "Scene",
    "SceneLayout",
    "Wall",
    "ball",
    "box",
    "build_scene",
    "check_scene_name",
    "cyl",
    "register_scene",
    "scene_names",
    "unregister_scene",
]
