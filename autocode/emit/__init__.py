"""The emitters, one file per backend, each a pure function of the checked
model returning `{relative path: text}`: sv.py (the state vector),
machine.py (each machine), app.py (the application's tables and entry
point), script.py (the state-script runners, host and tests only), graph.py
(`fsw graph`); expr.py and common.py are what the C++ backends share."""
