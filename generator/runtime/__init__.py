"""Vulkan runtime on Mesa lavapipe: device probing, eval kernels, renderer, hybrid.

Imports of the `vulkan` binding stay inside the submodules, so importing this
package works on machines without a Vulkan loader.
"""
