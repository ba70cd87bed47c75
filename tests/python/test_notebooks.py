"""Every notebook in notebooks/ executed headless (nbclient, a python3 kernel of this interpreter):
a notebook that raises fails the test. Skipped when the module or nbclient is missing."""
import glob
import os
import sys
import unittest

try:
    import dynlab  # noqa: F401  (the kernel imports it from the same PYTHONPATH)
    import nbclient
    import nbformat
except ImportError as e:
    print(f"DYNLAB_TEST_SKIPPED: {e}")
    sys.exit(0)

SOURCE = os.environ["DYNLAB_SOURCE_DIR"]
NOTEBOOKS = sorted(glob.glob(os.path.join(SOURCE, "notebooks", "*.ipynb")))


class Notebooks(unittest.TestCase):
    def test_there_are_notebooks(self):
        self.assertTrue(NOTEBOOKS)

    def test_every_notebook_runs(self):
        os.environ.setdefault("MPLBACKEND", "Agg")
        for path in NOTEBOOKS:
            with self.subTest(notebook=os.path.basename(path)):
                nb = nbformat.read(path, as_version=4)
                # The kernel: this interpreter (Debian's), whatever python3 kernelspec is installed.
                client = nbclient.NotebookClient(nb, timeout=600, kernel_name="python3",
                                                 resources={"metadata": {"path": os.path.dirname(path)}})
                client.execute()
                errors = [o for c in nb.cells if c.cell_type == "code" for o in c.get("outputs", [])
                          if o.get("output_type") == "error"]
                self.assertEqual(errors, [])


if __name__ == "__main__":
    unittest.main(verbosity=2)
