"""Force register: what the stress tensors are made of (spec §7.1, B.5).

The engine fills it with arrays once per force phase (per active pair: the
force on each sphere, the tangential torques and the internal/external flags;
per sphere: totals).  The six reference lists (``pair_register`` …) are built
on demand as ``[target, source, F]`` entries for the API; manual ``record_*``
calls (scripts without an ensemble) append to them directly.
"""
import numpy as np

__all__ = ["Force_register", "SphereSelection"]


def _live(p, flag):
    """Entries of a register block with ``flag`` set that are relations (engine blocks span all candidates)."""
    m = p[flag]
    active = p.get("active")
    return m if active is None else m & active


class PairBlock(dict):
    """Register block of the engine: per-pair arrays; ``fix``, ``fiy``, ``fjx``, ``fjy`` are the rows
    of the (2, P) force arrays ``Fi``, ``Fj``, made on first use."""

    _ROWS = {"fix": ("Fi", 0), "fiy": ("Fi", 1), "fjx": ("Fj", 0), "fjy": ("Fj", 1)}

    def __missing__(self, key):
        if key in self._ROWS:
            name, row = self._ROWS[key]
            value = self[name][row]
            self[key] = value
            return value
        raise KeyError(key)


class SphereSelection:
    """A list-like selection of an ensemble's spheres by boolean mask (no Python loop to build)."""

    def __init__(self, ensemble, mask=None):
        self.ensemble = ensemble
        self.mask = mask

    def indices(self):
        n = len(self.ensemble.sphereList)
        if self.mask is None:
            return np.arange(n)
        return np.flatnonzero(self.mask)

    def __iter__(self):
        sl = self.ensemble.sphereList
        return (sl[k] for k in self.indices())

    def __len__(self):
        return len(self.indices())

    def __getitem__(self, k):
        return self.ensemble.sphereList[self.indices()[k]]


class Force_register:
    """Per-step record of internal pair forces, external forces and torques."""

    def __init__(self):
        self.reset_force_register()

    def reset_force_register(self):
        """Clear everything (start of each force phase)."""
        self._ens = None
        self._blocks = []
        self._tot = None
        self._tot_block = None
        self._mom = None
        if getattr(self, "_manual", True):
            self._clear_manual()

    def _clear_manual(self):
        """Empty the lists that the manual ``record_*`` calls fill (only when something was recorded)."""
        self._manual = False
        self._m_pair = []
        self._m_ext = []
        self._m_imom = []
        self._m_emom = []
        self._m_tot = {}
        self._m_unb = {}

    # -- engine side -------------------------------------------------------------------------
    def _set_pairs(self, ensemble, pair):
        """Add one block of per-pair arrays (one per force phase, or per standalone term call)."""
        self._ens = ensemble
        self._blocks.append(pair)

    def _set_totals(self, ensemble, mobile, fx, fy, torque, block=None):
        self._ens = ensemble
        self._tot = (mobile, fx, fy)
        self._tot_block = np.array((fx, fy)) if block is None else block
        self._mom = torque

    # -- manual API (reference signatures) ----------------------------------------------------
    def record_individual_internal_force(self, target, source, force_vector):
        self._manual = True
        self._m_pair.append([target, source, list(force_vector)])

    def record_total_particle_force(self, target, force_vector):
        self._manual = True
        self._m_tot[id(target)] = [target, list(force_vector)]

    def record_external_force(self, target, force_vector):
        self._manual = True
        self._m_ext.append([target, list(force_vector)])

    def record_external_torque(self, target, moment):
        self._manual = True
        self._m_emom.append([target, moment])

    def record_individual_internal_torque(self, target, source, moment):
        self._manual = True
        self._m_imom.append([target, source, moment])

    def record_unbalanced_moment(self, target, moment):
        self._manual = True
        self._m_unb[id(target)] = [target, moment]

    # -- reference lists, built on demand ---------------------------------------------------------
    def _spheres(self):
        return self._ens.sphereList

    @property
    def pair_register(self):
        out = []
        for p in self._blocks:
            sl = self._spheres()
            for k in np.flatnonzero(_live(p, "internal")):
                i, j = int(p["i"][k]), int(p["j"][k])
                out.append([sl[i], sl[j], [float(p["fix"][k]), float(p["fiy"][k])]])
                out.append([sl[j], sl[i], [float(p["fjx"][k]), float(p["fjy"][k])]])
        return out + self._m_pair

    @property
    def external_force_register(self):
        out = []
        for p in self._blocks:
            sl = self._spheres()
            for k in np.flatnonzero(_live(p, "ext_i") | _live(p, "ext_j")):
                i, j = int(p["i"][k]), int(p["j"][k])
                if p["ext_i"][k]:
                    out.append([sl[i], [float(p["fix"][k]), float(p["fiy"][k])]])
                if p["ext_j"][k]:
                    out.append([sl[j], [float(p["fjx"][k]), float(p["fjy"][k])]])
        return out + self._m_ext

    def _moments(self, which):
        out = []
        for p in self._blocks:
            if p.get("ti") is None:
                continue
            sl = self._spheres()
            if which == "internal":
                for k in np.flatnonzero(_live(p, "internal")):
                    i, j = int(p["i"][k]), int(p["j"][k])
                    out.append([sl[i], sl[j], float(p["ti"][k])])
                    out.append([sl[j], sl[i], float(p["tj"][k])])
            else:
                for k in np.flatnonzero(_live(p, "ext_i") | _live(p, "ext_j")):
                    i, j = int(p["i"][k]), int(p["j"][k])
                    if p["ext_i"][k]:
                        out.append([sl[i], float(p["ti"][k])])
                    if p["ext_j"][k]:
                        out.append([sl[j], float(p["tj"][k])])
        return out

    @property
    def internal_moment_register(self):
        return self._moments("internal") + self._m_imom

    @property
    def external_moment_register(self):
        return self._moments("external") + self._m_emom

    @property
    def total_particle_force_register(self):
        out = []
        if self._tot is not None:
            mobile, fx, fy = self._tot
            sl = self._spheres()
            for k in np.flatnonzero(mobile):
                out.append([sl[k], [float(fx[k]), float(fy[k])]])
        return out + list(self._m_tot.values())

    @property
    def unbalanced_moment_register(self):
        out = []
        if self._mom is not None:
            sl = self._spheres()
            out = [[sl[k], float(t)] for k, t in enumerate(self._mom)]
        return out + list(self._m_unb.values())
