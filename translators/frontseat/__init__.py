"""Goby's stock helm plugin (FrontSeatTranslation): NAV_* from node_status, helm state and desired course from
pHelmIvP's DESIRED_* and IVPHELM_STATE."""
