"""The offline design tools of the classical controllers: linearisation of the flight model at frozen
times (:mod:`.linearize`), the discrete flight loop with servo, delay and gyro filter (:mod:`.flightloop`),
the rigid gain-schedule tuning (:mod:`.tune`), the flexible-vehicle PID design with structural filters
(:mod:`.flexdesign`, :mod:`.flexproblem`, :mod:`.flextable`), the LQG design (:mod:`.lqg_design`,
:mod:`.lqg_row`), the sensor-noise propagation (:mod:`.noise`) and the Bode and Nichols charts
(:mod:`.charts`).

Nothing here flies in an evaluation: the controllers (:mod:`lvgym.baselines`) read the schedules these
tools write, and never import them. They need python-control (``pip install 'lvgym[control]'``).
"""
