"""A policy that ends its own process at its first step (exit code 3), as a policy calling ``os._exit`` or a
native crash would: the study tests use it to make a cell kill the worker running it.

It is named through the Python API (a ``Component`` built by the test), never by a data file."""

import os

EXIT_CODE = 3


def act(obs):
    os._exit(EXIT_CODE)
