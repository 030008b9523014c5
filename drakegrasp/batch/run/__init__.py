"""The run: chunks, their stream, worker processes and shared memory.

One chunk of grasps start to finish (:mod:`~drakegrasp.batch.run.chunk`), the
chunk stream (:mod:`~drakegrasp.batch.run.stream`), worker processes and the
shared memory that feeds them.
"""
