"""Plants that ship with the package: the MuJoCo physics hand (``mujoco_plant``, extra ``[mujoco]``)."""
