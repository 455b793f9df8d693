"""The engine layer (layer 1 of :data:`particleShear.layers.LAYERS`): array kernels with a leading
replica axis (``docs/engine.md``).

The engine advances B independent replicas of the measurement (pre-equilibration with plates,
then the oscillatory protocol) in one set of flat arrays: spheres of replica b occupy rows
``b·N … b·N + N − 1``, pairs are kept per replica in canonical ``(i, j)`` order, and every sum
over a replica is a reduction over its own rows (a segment of the pair or sphere arrays), so a
replica's numbers do not depend on the other replicas of its batch.

Modules, bottom-up: :mod:`.box` (Lees-Edwards geometry), :mod:`.laws` (central laws),
:mod:`.tangential` (the two-visit tangential rule, shared with the canvas classes),
:mod:`.state` (the batch state; its contacts, :mod:`.contacts`, and its Verlet predictor,
:mod:`.predictor`), :mod:`.neighbours` (Verlet candidates per replica from a cell list; also the
classes' neighbour search), :mod:`.relax` (the constitution's free relaxation of a
batch),
:mod:`.terms` (the force terms of a pair, each written once: kinematics, term constants, elastic,
viscous and tangential terms, force vectors and torque split; shared with the canvas classes),
:mod:`.forces` (per-candidate constants, geometry, scatter, shear stresses), :mod:`.integrate` (kick,
the Verlet half kick, plates, damping, the sequential ξ rule and the drift, shared with the canvas classes), :mod:`.stress` (every tensor once, in one
registry; also the classes' tensors), :mod:`.step` (one step, top to bottom, the
pre-equilibration and the protocol), :mod:`.observers` (what the loops call to watch a run
without changing it: drawing, snapshots, the live stress window); :mod:`.xp` is the array namespace (NumPy, or CuPy with
``backend="cupy"``) and the one door from the device to the host (docs/backends.md).
"""
__docformat__ = "numpy"
