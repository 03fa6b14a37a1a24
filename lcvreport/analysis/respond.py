"""The response of any model of a vehicle to a manoeuvre (docs/model.md#the-model-object): a linear
model's exact response (:func:`lcvreport.analysis.exact.response`), any other model integrated
(:func:`lcvreport.analysis.integrate.integrate`) -- one call for the measures, whatever the model.

Examples
--------
>>> from lcvreport import load_vehicle
>>> from lcvreport.manoeuvres.steer import sine
>>> v = load_vehicle("examples/vehicles/b_double.toml")
>>> a = respond(v, "yaw_plane", sine(0.01, 0.4), 22.0, 8.0, 0.05)
>>> b = respond(v, "nonlinear", sine(0.01, 0.4), 22.0, 8.0, 0.05, options={"tire": "linear"})
>>> bool(abs(a.peak_abs("ay3") / b.peak_abs("ay3") - 1) < 1e-3)       # small angles: nearly the same
True
"""
from __future__ import annotations

from ..model.base import build_model, check_model


def respond(vehicle, model: str, steer, speed_mps: float, t_end: float, dt: float, tire_scale: float = 1.0,
            F=None, sources=None, options: dict | None = None):
    """The response of ``vehicle``'s model ``model`` to ``steer`` from rest at ``speed_mps`` [m/s],
    sampled every ``dt`` to ``t_end`` [s] (a :class:`~lcvreport.analysis.time_response.Response`).

    Parameters
    ----------
    vehicle : Vehicle
    model : str
        A key of :data:`lcvreport.model.base.MODELS`.
    steer : SteerInput
    speed_mps, t_end, dt : float
    tire_scale : float
    F : numpy.ndarray, optional
        A linear model's generalized force of the residual sources (its exact response's).
    sources : ResidualSources, optional
        The residual sources (on a linear model added to ``F``, their axle forces to its tire
        force outputs).
    options : dict, optional
        The model's options (the nonlinear model's ``tire`` and ``friction_coefficient``) and
        the integration's ``rtol`` (default :data:`lcvreport.analysis.integrate.RTOL`).

    Returns
    -------
    TimeResponse or SampledResponse

    Examples
    --------
    >>> from lcvreport import load_vehicle
    >>> from lcvreport.manoeuvres.steer import sine
    >>> r = respond(load_vehicle("examples/vehicles/b_double.toml"), "yaw_roll", sine(0.01, 0.4), 24.4, 6.0, 0.05)
    >>> "phi3" in r.names
    True
    """
    from ..model import linear
    if str(model).replace("-", "_") in linear.MODELS:         # a linear model (a registered one too)
        from .exact import response
        axle_force = None
        if sources:                                             # lcv simulate's --residual/--misalignment/...
            name = str(model).replace("-", "_")
            F = sources.vector(vehicle, tire_scale, name) + (0.0 if F is None else F)
            axle_force = sources.axle_forces(vehicle, tire_scale)
        return response(vehicle, speed_mps, steer, t_end, dt, F=F, tire_scale=tire_scale, model=model,
                        axle_force_N=axle_force)
    name = check_model(model)
    from .integrate import RTOL, integrate
    options = dict(options or {})
    rtol = options.pop("rtol", RTOL)
    return integrate(build_model(vehicle, name, **options), steer, speed_mps, t_end, dt, tire_scale,
                     sources=sources, rtol=rtol)
