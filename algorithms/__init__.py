"""The robots' minds: pure Python, never importing MuJoCo.

An algorithm sees what a real robot would see (its own sensor readings, the beacon
at the vertex it stands on, the radio messages it received) and answers with
decisions (next edge, speed factor, messages to send, role).
"""
