"""The graph of an ensemble's bonds: particles as its components, and whether a bond can go.

A crosslinked ensemble's particles are the connected components of its permanent pairs
(``i, j``: sphere rows).  The builders and the documented classes label particles with
:func:`component_labels`; removing links (``remove_non_essential_links``) keeps a particle whole
by testing :func:`connected_without_edge` on the :func:`adjacency` sets.
"""
__docformat__ = "numpy"

import numpy as np

__all__ = ["component_labels", "adjacency", "connected_without_edge"]


def component_labels(n, i, j):
    """Label each of ``n`` nodes with the smallest node of its component (min-label propagation, pointer jumping).

    The particles of a crosslinked ensemble are the components of its bonds (``i, j``: the
    permanent pairs); the loop ends because labels only decrease, after at most ``n`` rounds.

    Parameters
    ----------
    n : int
        Number of nodes (spheres).
    i, j : array_like of int
        End nodes of the edges.

    Returns
    -------
    numpy.ndarray of int (n,)
        The smallest node of each node's component.
    """
    lab = np.arange(n, dtype=np.intp)
    i = np.asarray(i, dtype=np.intp)
    j = np.asarray(j, dtype=np.intp)
    if not len(i):
        return lab
    while True:
        li, lj = lab[i], lab[j]
        m = np.minimum(li, lj)
        new = lab.copy()
        # hook both the nodes and their current labels (roots) onto the smaller label
        np.minimum.at(new, li, m)
        np.minimum.at(new, lj, m)
        np.minimum.at(new, i, m)
        np.minimum.at(new, j, m)
        while True:  # pointer jumping: every node points at its root
            nn = new[new]
            if np.array_equal(nn, new):
                break
            new = nn
        if np.array_equal(new, lab):
            return lab
        lab = new


def adjacency(n, i, j):
    """Neighbour sets per node of the undirected graph with edges ``i–j``.

    Parameters
    ----------
    n : int
        Number of nodes (spheres).
    i, j : numpy.ndarray of int
        End nodes of the edges.

    Returns
    -------
    list of set
        ``adj[p]``: the nodes joined to p by an edge.
    """
    adj = [set() for _ in range(n)]
    for p, q in zip(i.tolist(), j.tolist()):
        adj[p].add(q)
        adj[q].add(p)
    return adj


def connected_without_edge(adj, p, q):
    """Whether q is reachable from p without the edge p–q (bidirectional breadth-first search, early
    exit; each node is visited once, so at most ``len(adj)`` rounds).

    Parameters
    ----------
    adj : list of set
        The graph (:func:`adjacency`).
    p, q : int
        The two ends of the edge left out.

    Returns
    -------
    bool
        True if another path joins p and q.
    """
    front_a, seen_a = [p], {p}
    front_b, seen_b = [q], {q}
    while front_a and front_b:
        if len(front_a) > len(front_b):
            front_a, seen_a, front_b, seen_b = front_b, seen_b, front_a, seen_a
        nxt = []
        for u in front_a:
            for w in adj[u]:
                if (u == p and w == q) or (u == q and w == p):
                    continue
                if w in seen_b:
                    return True
                if w not in seen_a:
                    seen_a.add(w)
                    nxt.append(w)
        front_a = nxt
    return False
