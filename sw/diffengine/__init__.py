"""diffengine: golden model and tools for the Difference Engine x-processor array.

The package imports nothing from cocotb, so the model can be used and tested alone.
"""
__version__ = "0.1.0"
