//! The models shipped with moreau, each compiled from its YAML file in this
//! folder by `moreau::model!`:
//!
//! | type | file | N | K | what |
//! |---|---|---|---|---|
//! | [`Parabola`] | `parabola.yaml` | 2 | 2 | the paper's Example 1 (Fig. 1b, Fig. 4) |
//! | [`ThreeBalls`] | `three_balls.yaml` | 3 | 4 | Fig. 1a: three balls between two walls |
//! | [`Billiard`] | `billiard.yaml` | 2 | 4 | Fig. 1c: a nonconvex billiard with inward-curving walls |
//! | [`DoublePendulum`] | `double_pendulum.yaml` | 2 | 2 | a double pendulum whose tip hits a wall and a floor |
//! | [`Arm3`] | `arm3.yaml` | 3 | 1 | a three-link arm with a wall at its tip |
//! | [`Chain2`] .. [`Chain12`] | `chains/chainNN.yaml` | N | N | planar N-link chains (unit masses, one floor gap per mass), written by `chains/gen.py`, for scaling benchmarks |
//!
//! ```
//! use moreau::Model;
//! use moreau_models::Parabola;
//!
//! let model = Parabola::<f64>::new();
//! let (q0, v0) = Parabola::<f64>::initial_state();
//! let (h, _j) = model.contact(&q0);
//! assert!(h.iter().all(|&gap| gap >= 0.0));
//! assert_eq!(Parabola::<f64>::INFO.constraints, ["floor", "ceiling"]);
//! # let _ = v0;
//! ```

moreau::model!(file = "parabola.yaml");
moreau::model!(file = "three_balls.yaml");
moreau::model!(file = "billiard.yaml");
moreau::model!(file = "double_pendulum.yaml");
moreau::model!(file = "arm3.yaml");
moreau::model!(file = "chains/chain02.yaml");
moreau::model!(file = "chains/chain03.yaml");
moreau::model!(file = "chains/chain04.yaml");
moreau::model!(file = "chains/chain05.yaml");
moreau::model!(file = "chains/chain06.yaml");
moreau::model!(file = "chains/chain07.yaml");
moreau::model!(file = "chains/chain08.yaml");
moreau::model!(file = "chains/chain09.yaml");
moreau::model!(file = "chains/chain10.yaml");
moreau::model!(file = "chains/chain11.yaml");
moreau::model!(file = "chains/chain12.yaml");
