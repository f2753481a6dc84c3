"""hierhand: hierarchical grasping/manipulation control of a three-fingered hand, as blocks.

The application is built only on the public API of the ``blocks`` framework; this
package also provides the ``hierhand`` command line.
"""
