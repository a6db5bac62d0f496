"""Compensation: the model applied to data.

kernels   pure functions and streaming state on arrays (batch equals streaming)
files     the chunked file driver at the edge: reads a recording in chunks, writes the output
          through a temporary and renames it
"""
