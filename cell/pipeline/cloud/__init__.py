"""A brought point cloud to located seams (``cell locate``): the table found or told, the map aligned on the cloud
(`locate`), the cell and the locator's options set up from the data (`setup`) and the seams located (`seams`),
never importing the simulator (docs/locate.md, "From the cloud to the seams")."""

from cell.pipeline.cloud.locate import locate_cloud

__all__ = ["locate_cloud"]
