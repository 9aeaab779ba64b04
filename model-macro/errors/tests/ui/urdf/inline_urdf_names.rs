// URDF names that become the same name of the model are refused, both
// pairs at once, each naming the two.
moreau::model! {
    pub struct Clashing;
    urdf = "tests/ui/yaml/clashing_names.urdf";
    restitution = 0.5;
}

fn main() {}
