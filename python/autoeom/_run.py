"""The result of System.run: the rows eom-run would write, as arrays."""
import numpy as np


class Run:
    """A run: ``t`` (rows), ``x`` (rows x 2n states), ``q``, ``qd``,
    the energy columns ``T``, ``V``, ``E``, ``W``, ``probes``,
    ``multipliers`` (when asked for with columns=["multipliers"]),
    ``sensitivities`` (rows x 2n x inputs, with sensitivity=[...]), the
    whole table ``data`` with its column ``names`` (those of eom-run's CSV,
    docs/csv.md), and the integrator's ``stats``. ``run["name"]`` is one
    column; ``run.dataframe()`` the table as a pandas DataFrame."""

    def __init__(self, system, names, data, stats, sens_names, n_sens,
                 groups=()):
        n, m = system.ncoords, system.nconstraints
        self.names = list(names) + list(sens_names)
        self.data = data
        self.stats = stats
        self._index = {name: k for k, name in enumerate(self.names)}
        self.t = data[:, 0]
        self.x = data[:, 1:1 + 2 * n]
        self.q = self.x[:, :n]
        self.qd = self.x[:, n:]
        for key in ("T", "V", "E", "W"):
            setattr(self, key, data[:, self._index[key]])
        # the CSV's order (docs/csv.md): phi, phidot, probes, then the
        # optional groups in a fixed order; by position, as a probe may
        # have any name
        first = self._index["W"] + 1 + 2 * m
        self.probes = data[:, first:first + system.nprobes]
        at = first + system.nprobes
        self.accelerations = self.multipliers = None
        if "accelerations" in groups:
            self.accelerations = data[:, at:at + n]
            at += n
        if "multipliers" in groups:
            self.multipliers = data[:, at:at + m]
        if n_sens:
            tail = data[:, len(names):]
            self.sensitivities = tail.reshape(len(data), n_sens,
                                              2 * n).transpose(0, 2, 1)
        else:
            self.sensitivities = None

    def __getitem__(self, name):
        return self.data[:, self._index[name]]

    def __len__(self):
        return len(self.data)

    def dataframe(self):
        """The table as a pandas DataFrame (needs pandas: Debian's
        python3-pandas)."""
        import pandas
        return pandas.DataFrame(self.data, columns=self.names)

    def __repr__(self):
        return "<autoeom.Run: %d rows, t = %g .. %g, %d columns>" % (
            len(self.data), self.t[0] if len(self.t) else np.nan,
            self.t[-1] if len(self.t) else np.nan, len(self.names))
