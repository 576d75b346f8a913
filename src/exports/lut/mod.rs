//! `smithwalk lut`: energy-compensation tables. The directional albedo E(mu, alpha) of the
//! Smith microsurface per bounce order and for all orders (docs/theory.md §9.4), and its cosine-
//! weighted hemispherical average E_avg(alpha) = 2 ∫ E(mu) mu dmu, for the conductor with F = 1
//! (the Kulla-Conty tables), the dielectric E(mu, alpha, eta) in reflection and transmission
//! from both sides, and the `hammon` facet, on GGX or Beckmann (`[surface] ndf`, recorded in
//! `lut.json`). Every value is a walk measurement with its standard error; cells stop at a
//! requested standard error.
//!
//! The table grids are cell centres, mu_i = (i + 1/2) / n_mu and likewise alpha and eta over
//! their ranges, or with `nodes = "edges"` the ranges' end points and between them evenly. A
//! node at alpha = 0 is the flat surface, exact (`flat`); a node at mu = 0 is walked at
//! [`MU_GRAZING`]. E_avg is a Gauss–Legendre sum over its own incidence nodes in mu (E is smooth
//! in mu, so the rule's error is far below the statistical one), not a sum over the table grid.
//!
//! The configuration is in `config`, the walk and the tables in `tables`, the flat surface in
//! `flat`, the files in `formats`.

mod config;
mod flat;
mod formats;
mod tables;

pub use crate::io::table_record::{Nodes, TableKind, TableRecord};
pub use config::{LutConfig, MU_GRAZING, TableConfig};
pub use formats::{c_header, csv_avg, csv_table, exr_image, rust_source, write};
pub use tables::{Lut, Quantity, QuantityTable, build};
